#include "cranioplan/algorithms/planning/trace_rim.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>

#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/geometry/voxelize_mesh.h"
#include "cranioplan/algorithms/io/extract_bone_surface.h"
#include "cranioplan/algorithms/planning/detect_defect.h"
#include "cranioplan/algorithms/quality/inject_defect.h"
#include "cranioplan/model/parallel.h"
#include "support/synthetic.h"

namespace cranioplan {
namespace {

constexpr double kDeg = M_PI / 180.0;

// A flap cut out of the side of a thick head whose lower edge lies just above a shelf of bone
// inside the head (as the middle fossa's floor and the sphenoid ridge lie below a decompressive
// craniectomy's lower edge): a floor plate joined to the lateral wall 4 mm below the cut, and a
// ridge standing 17 mm high on it 20-30 mm in from the wall. Seen from a point high in the cavity,
// the ridge hides the flap's lower edge: no ray meets its last bone there.
struct ShelfedFlap {
  FlapCut flap;
  SkullMesh defective;
};

const ShelfedFlap& shelfed_flap() {
  static const ShelfedFlap c = [] {
    ShelfedFlap k;
    const SkullMesh outer = test::make_symmetric_head(5);
    SkullMesh inner = outer;
    for (auto vh : inner.vertices()) inner.set_point(vh, inner.point(vh) * 0.93);
    const auto [lo, hi] = mesh_bounds(outer);
    const VoxelGrid grid = VoxelGrid::covering(lo, hi, 0.5);
    const std::vector<uint8_t> head = voxelize_mesh(outer, grid),
                               cavity = voxelize_mesh(inner, grid);
    k.flap.apex = Eigen::Vector3d::Zero();
    k.flap.axis = Eigen::Vector3d(1.0, 0.0, 0.45).normalized();
    k.flap.along = unit_across(Eigen::Vector3d::UnitY(), k.flap.axis);
    k.flap.half_length_rad = 40.0 * kDeg;
    k.flap.half_width_rad = 38.0 * kDeg;
    k.flap.floor = Plane{Eigen::Vector3d::UnitZ(), -8.0};  // bone below z = −8 is kept
    std::vector<uint8_t> bone(head.size(), 0);
    for (int z = 0; z < grid.dims[2]; ++z)
      for (int y = 0; y < grid.dims[1]; ++y)
        for (int x = 0; x < grid.dims[0]; ++x) {
          const size_t i = grid.index(x, y, z);
          if (!head[i]) continue;
          const Eigen::Vector3d p = grid.center(x, y, z);
          const bool plate = p.z() >= -15.0 && p.z() <= -12.0 && p.x() >= 30.0;
          const bool ridge = p.z() >= -15.0 && p.z() <= 2.0 && p.x() >= 30.0 && p.x() <= 40.0 &&
                             std::abs(p.y()) <= 45.0;
          bone[i] = (!cavity[i] && !k.flap.contains(p)) || plate || ridge;
        }
    ExtractBoneSurfaceParams all;
    all.largest_piece_only = false;
    all.min_piece_triangles = 1;
    k.defective = extract_bone_surface(mask_volume(bone, grid), all).mesh;
    return k;
  }();
  return c;
}

// The flap's edge on the head's outer surface, found by bisection along great circles from its
// axis every degree of bearing.
std::vector<Eigen::Vector3d> true_rim(const FlapCut& flap) {
  const Eigen::Vector3d e2 = flap.axis.cross(flap.along);
  std::vector<Eigen::Vector3d> rim;
  for (int deg = 0; deg < 360; ++deg) {
    const double phi = deg * kDeg;
    auto surface = [&](double beta) {
      const Eigen::Vector3d d = std::cos(beta) * flap.axis +
                                std::sin(beta) * (std::cos(phi) * flap.along + std::sin(phi) * e2);
      return test::head_surface_point(d.normalized());
    };
    double in = 0.0, out = 1.4;
    for (int it = 0; it < 50; ++it) {
      const double mid = 0.5 * (in + out);
      (flap.contains(surface(mid)) ? in : out) = mid;
    }
    rim.push_back(surface(in));
  }
  return rim;
}

double distance_to_polyline(const Eigen::Vector3d& p, const std::vector<Eigen::Vector3d>& loop) {
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < loop.size(); ++i) {
    const Eigen::Vector3d& a = loop[i];
    const Eigen::Vector3d& b = loop[(i + 1) % loop.size()];
    const double t =
        std::clamp((p - a).dot(b - a) / std::max(1e-12, (b - a).squaredNorm()), 0.0, 1.0);
    best = std::min(best, (a + t * (b - a) - p).norm());
  }
  return best;
}

// Rays from high in the cavity cannot see the flap's lower edge behind the ridge: the rim they
// find is interpolated there. Traced on the bone, the rim runs along the flap's true edge all
// round, within a millimetre, and the opening is every ray inside it.
TEST(TraceRim, FindsTheEdgeTheRaysCannotSee) {
  const ShelfedFlap& c = shelfed_flap();
  const SurfaceLocator bone(c.defective);
  const Eigen::Vector3d start(0.0, 0.0, 5.0);
  DetectDefectParams rays_only;
  rays_only.trace_rim_on_bone = false;
  rays_only.scan_borders = std::vector<ScanBorder>{};
  const DefectRegion seen = detect_defect(c.defective, bone, start, rays_only);
  ASSERT_TRUE(seen.found()) << seen.message;
  const std::vector<Eigen::Vector3d> truth = true_rim(c.flap);
  // The rays' rim misses the lower edge: where they meet the ridge instead, or not at all.
  double seen_off = 0.0;
  for (const Eigen::Vector3d& p : truth)
    seen_off = std::max(seen_off, distance_to_polyline(p, seen.outer_rim));
  RecordProperty("rays_worst_mm", std::to_string(seen_off));
  ASSERT_GT(seen_off, 10.0) << "the rays saw the whole rim: no shelf hides it";

  DetectDefectParams traced = rays_only;
  traced.trace_rim_on_bone = true;
  const DefectRegion found = detect_defect(c.defective, bone, start, traced);
  ASSERT_TRUE(found.found()) << found.message;
  ASSERT_TRUE(found.rim_traced);
  EXPECT_TRUE(found.unseen_rim.empty());
  EXPECT_TRUE(found.at_scan_border.empty());
  EXPECT_EQ(found.message.find("not seen"), std::string::npos) << found.message;

  double worst_traced = 0.0, worst_true = 0.0;
  double mean_traced = 0.0;
  for (const Eigen::Vector3d& p : found.outer_rim) {
    const double d = distance_to_polyline(p, truth);
    mean_traced += d / found.outer_rim.size();
    worst_traced = std::max(worst_traced, d);
  }

  for (const Eigen::Vector3d& p : truth)
    worst_true = std::max(worst_true, distance_to_polyline(p, found.outer_rim));
  RecordProperty("worst_traced_mm", std::to_string(worst_traced));
  RecordProperty("worst_true_mm", std::to_string(worst_true));
  RecordProperty("mean_traced_mm", std::to_string(mean_traced));
  // The surface is meshed from 0.5 mm voxels (its staircase and its corners' rounding); the
  // rays' rim is 30 mm off along the lower edge.
  EXPECT_LT(mean_traced, 0.5);
  EXPECT_LT(worst_traced, 1.5) << "a traced rim point lies off the flap's edge";
  EXPECT_LT(worst_true, 1.5) << "a stretch of the flap's edge was missed";
  // Rays seen every ~1.5° of the rim; the rim points about a millimetre apart.
  EXPECT_GT(found.outer_rim.size(), 300u);
  EXPECT_GT(found.area_mm2, seen.area_mm2);
}

// The two tables are traced side by side: the rim is the same on one thread and on two.
TEST(TraceRim, TheTracedRimIsTheSameOnOneThreadAndOnTwo) {
  const ShelfedFlap& c = shelfed_flap();
  const SurfaceLocator bone(c.defective);
  DetectDefectParams traced;
  traced.scan_borders = std::vector<ScanBorder>{};
  std::vector<Eigen::Vector3d> outer[2], inner[2];
  for (int threads : {1, 2}) {
    set_thread_count(threads);
    const DefectRegion found =
        detect_defect(c.defective, bone, Eigen::Vector3d(0.0, 0.0, 5.0), traced);
    set_thread_count(0);
    ASSERT_TRUE(found.rim_traced) << found.message;
    outer[threads - 1] = found.outer_rim;
    inner[threads - 1] = found.inner_rim;
  }
  EXPECT_EQ(outer[0], outer[1]);
  EXPECT_EQ(inner[0], inner[1]);
  EXPECT_FALSE(inner[0].empty());
}

}  // namespace
}  // namespace cranioplan
