#include "cranioplan/algorithms/implant/trim_to_bone.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>

#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/geometry/voxelize_mesh.h"
#include "cranioplan/algorithms/io/mesh_report.h"
#include "cranioplan/algorithms/quality/check_implant.h"
#include "support/synthetic.h"

namespace cranioplan {
namespace {

TriangleSoup box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  return test::box_soup(lo, hi);
}

SkullMesh merge(const TriangleSoup& a, const TriangleSoup& b) {
  TriangleSoup s = a;
  const int n = static_cast<int>(s.vertices.size());
  s.vertices.insert(s.vertices.end(), b.vertices.begin(), b.vertices.end());
  for (auto t : b.triangles) s.triangles.push_back({t[0] + n, t[1] + n, t[2] + n});
  return build_mesh(s);
}

// The plates most tests stand on: 5 mm thick, 20 mm wide, a 10 mm gap (the defect) between
// them along x; with `exchange_xz` the same scene with x and z exchanged.
SkullMesh gap_plates(bool exchange_xz = false) {
  auto p = [&](double x, double y, double z) {
    return exchange_xz ? Eigen::Vector3d(z, y, x) : Eigen::Vector3d(x, y, z);
  };
  return merge(box(p(0, 0, 0), p(20, 20, 5)), box(p(30, 0, 0), p(50, 20, 5)));
}

// An implant over the gap, 3 mm wider on both sides and 0.3 mm proud of the plates' tops.
TriangleSoup gap_implant(bool exchange_xz = false) {
  return exchange_xz ? box({0, 2, 17}, {5.3, 18, 33}) : box({17, 2, 0}, {33, 18, 5.3});
}

// The largest coordinate `axis` of the mesh's vertices.
double highest(const SkullMesh& m, int axis) {
  double x = -1e9;
  for (auto vh : m.vertices()) x = std::max(x, static_cast<double>(m.point(vh)[axis]));
  return x;
}

// Bone: the two plates with their 10 mm gap; the implant 3 mm wider on both sides and 0.3 mm
// proud of the bone (gap_implant): trimmed, it fills the gap — against both cut faces, no
// overlap, and no sliver left on top of the bone.
TEST(TrimToBone, FillsTheGapFlushWithTheCutFaces) {
  const SkullMesh bone = gap_plates();
  const SkullMesh implant = build_mesh(gap_implant());
  const TrimToBoneResult r = trim_to_bone(implant, bone);
  ASSERT_TRUE(r.usable()) << r.message;
  EXPECT_TRUE(report_mesh(r.mesh).watertight);
  EXPECT_GT(signed_volume(to_soup(r.mesh)), 0.0) << "outward";
  // Truth: [20, 30] x [2, 18] x [0, 5.3] = 848 mm³. The bridge fills cracks only (bone and
  // implant on opposite sides), so no fillet grows where the walls meet the plates' tops.
  EXPECT_GE(r.volume_mm3, 0.95 * 848.0);
  EXPECT_LE(r.volume_mm3, 1.05 * 848.0);
  for (auto vh : r.mesh.vertices()) {
    const Eigen::Vector3d p = to_eigen(r.mesh.point(vh));
    if (p.x() < 19.5 || p.x() > 30.5) ADD_FAILURE() << "over a plate at " << p.transpose();
  }
  const auto [lo, hi] = [&] {
    Eigen::Vector3d a = Eigen::Vector3d::Constant(1e9), b = -a;
    for (auto vh : r.mesh.vertices()) {
      a = a.cwiseMin(to_eigen(r.mesh.point(vh)));
      b = b.cwiseMax(to_eigen(r.mesh.point(vh)));
    }
    return std::make_pair(a, b);
  }();
  // Against both cut faces, never into the bone, at most half a millimetre off it (the rim-gap
  // target); the grid's alignment decides where in that range.
  EXPECT_GE(lo.x(), 19.0);
  EXPECT_LE(lo.x(), 20.5) << "against the left cut face";
  EXPECT_LE(hi.x(), 31.0);
  EXPECT_GE(hi.x(), 29.5) << "against the right cut face";
  const QualityReport q = check_implant(r.mesh, &bone);
  EXPECT_EQ(q.penetration_mm3, 0.0);
}

// The same scene with x and z exchanged: the grid is then thin along x and long along z (more
// slices than voxels in a row), and the fit fills the gap just the same (a guard on the blur's
// bookkeeping of empty rows, which must not mix one axis's length with another's).
TEST(TrimToBone, FillsTheGapOnAGridLongerAlongZThanAlongX) {
  const SkullMesh bone = gap_plates(true);
  const SkullMesh implant = build_mesh(gap_implant(true));
  const TrimToBoneResult r = trim_to_bone(implant, bone);
  ASSERT_TRUE(r.usable()) << r.message;
  EXPECT_TRUE(report_mesh(r.mesh).watertight);
  EXPECT_GE(r.volume_mm3, 0.95 * 848.0);
  EXPECT_LE(r.volume_mm3, 1.05 * 848.0);
  EXPECT_NEAR(signed_volume(to_soup(r.mesh)), 848.0, 0.06 * 848.0);
}

// Meshed into a mesh the caller gives (one that held something else), the fit is the mesh the
// result would hold, and the result's own mesh stays empty; when nothing is left, the given
// mesh holds the implant as it came.
TEST(TrimToBone, MeshedIntoAGivenMeshAsItWouldBeReturned) {
  const SkullMesh bone = gap_plates();
  const SkullMesh implant = build_mesh(gap_implant());
  const TrimToBoneResult returned = trim_to_bone(implant, bone);
  SkullMesh into = build_mesh(box({-5, -5, -5}, {5, 5, 5}));
  const TrimToBoneResult given = trim_to_bone(implant, bone, {}, into);
  ASSERT_TRUE(given.usable()) << given.message;
  EXPECT_EQ(given.mesh.n_vertices(), 0u);
  EXPECT_EQ(given.volume_mm3, returned.volume_mm3);
  EXPECT_EQ(given.removed_mm3, returned.removed_mm3);
  const TriangleSoup a = to_soup(returned.mesh), b = to_soup(into);
  EXPECT_EQ(a.vertices, b.vertices);
  EXPECT_EQ(a.triangles, b.triangles);

  const SkullMesh buried = build_mesh(box({2, 2, 1}, {8, 8, 4}));
  const TrimToBoneResult nothing = trim_to_bone(buried, bone, {}, into);
  EXPECT_FALSE(nothing.usable());
  EXPECT_EQ(to_soup(into).triangles, to_soup(buried).triangles);
}

// An implant that stops 1.2 mm short of a cut face (ragged bone it was not extended to) is
// bridged onto it; without the bridge the crack stays.
TEST(TrimToBone, BridgesANarrowGapToTheBone) {
  const SkullMesh bone = gap_plates();
  const SkullMesh implant = build_mesh(box({17, 2, 0.5}, {28.8, 18, 4.5}));
  const TrimToBoneResult bridged = trim_to_bone(implant, bone);
  TrimToBoneParams off;
  off.bridge_mm = 0.0;
  const TrimToBoneResult cracked = trim_to_bone(implant, bone, off);
  ASSERT_TRUE(bridged.usable() && cracked.usable());
  auto right_end = [](const SkullMesh& m) { return highest(m, 0); };
  EXPECT_GE(right_end(bridged.mesh), 29.5) << "rests on the right cut face";
  EXPECT_LE(right_end(bridged.mesh), 30.0) << "never into it";
  EXPECT_LE(right_end(cracked.mesh), 29.0) << "without the bridge, the crack stays";
  EXPECT_EQ(check_implant(bridged.mesh, &bone).penetration_mm3, 0.0);
}

SkullMesh turned(const SkullMesh& m, const Eigen::Matrix3d& r) {
  SkullMesh out = m;
  for (auto vh : out.vertices()) out.set_point(vh, to_point(r * to_eigen(out.point(vh))));
  return out;
}

// Distances to the bone from the implant's vertices on its walls against the cut faces
// (x = 20 and x = 30 before turning, away from the plates' edges).
std::vector<double> wall_distances(const SkullMesh& implant, const SkullMesh& bone,
                                   const Eigen::Matrix3d& r) {
  const SurfaceLocator locator(bone);
  std::vector<double> d;
  for (auto vh : implant.vertices()) {
    const Eigen::Vector3d p = to_eigen(implant.point(vh)), q = r.transpose() * p;
    const bool on_wall = std::min(std::abs(q.x() - 20), std::abs(q.x() - 30)) < 1.0;
    if (on_wall && q.z() > 1 && q.z() < 4 && q.y() > 4 && q.y() < 16)
      d.push_back(locator.closest(p).distance);
  }
  std::sort(d.begin(), d.end());
  return d;
}

// The fitted field is meshed kept off its iso-level: a value at or next to ½ puts a vertex on
// or next to a grid point, where the edges meeting there fall together into triangles without
// area (their neighbours then seem to cross in the quality report). The gap's plates turned
// 0.3 rad: the smallest triangle 8e-7 mm², and 5e-11 mm² meshed as the field comes
// (build_implant commands before version 11), from the same voxels.
TEST(TrimToBone, MeshesNoTriangleWithoutArea) {
  const Eigen::Matrix3d r =
      (Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized())).toRotationMatrix();
  const SkullMesh bone = turned(gap_plates(), r);
  const SkullMesh implant = turned(build_mesh(gap_implant()), r);
  auto without_area = [](const SkullMesh& m) {
    int n = 0;
    for (auto fh : m.faces()) n += 0.5 * face_corners(m, fh).cross().norm() < 1e-8;
    return n;
  };
  TrimToBoneParams then;
  then.iso_gap = false;
  const TrimToBoneResult now = trim_to_bone(implant, bone);
  const TrimToBoneResult before = trim_to_bone(implant, bone, then);
  ASSERT_TRUE(now.usable() && before.usable());
  EXPECT_EQ(without_area(now.mesh), 0);
  EXPECT_GT(without_area(before.mesh), 0);
  EXPECT_EQ(now.volume_mm3, before.volume_mm3) << "the same voxels";
  EXPECT_TRUE(report_mesh(now.mesh).watertight);
}

// The gap between two plates, turned obliquely to every axis and trimmed on a coarse grid
// (0.45 mm, as for a large implant): the implant's walls lie the clearance (0.1 mm) off the cut
// faces to a fraction of the grid, not where the bone's voxels end. Without a clearance (the
// bone's voxels grown by one kept out, build_implant 3) it lies about a voxel off.
TEST(TrimToBone, HoldsTheClearanceOffObliqueCutFacesOnACoarseGrid) {
  const Eigen::Matrix3d r =
      (Eigen::AngleAxisd(0.5, Eigen::Vector3d(1, 2, 3).normalized())).toRotationMatrix();
  const SkullMesh bone = turned(gap_plates(), r);
  const SkullMesh implant = turned(build_mesh(gap_implant()), r);
  TrimToBoneParams coarse;
  coarse.max_voxels = 1e5;  // about 0.45 mm over this implant
  TrimToBoneParams then = coarse;
  then.clearance_mm.reset();
  const TrimToBoneResult now = trim_to_bone(implant, bone, coarse);
  const TrimToBoneResult before = trim_to_bone(implant, bone, then);
  ASSERT_TRUE(now.usable() && before.usable());
  const std::vector<double> d = wall_distances(now.mesh, bone, r),
                            e = wall_distances(before.mesh, bone, r);
  ASSERT_GT(d.size(), 100u);
  ASSERT_GT(e.size(), 100u);
  const double median = d[d.size() / 2], median_before = e[e.size() / 2];
  EXPECT_NEAR(median, 0.1, 0.05) << "the clearance";
  EXPECT_LE(d[d.size() * 95 / 100], 0.2);
  EXPECT_GT(median_before, 0.3) << "the voxel rule left the implant off the bone";
  EXPECT_EQ(check_implant(now.mesh, &bone).penetration_mm3, 0.0);
  EXPECT_TRUE(report_mesh(now.mesh).watertight);
}

// A fragment of bone 1 mm across floats 2.5 mm above the implant, within the bridge's reach
// (3 mm here): the bridge fills the crack between them, but that fill is a rod thinner than the
// feature size, most of it over a millimetre from the bone, and goes; the implant ends at its
// own top. With fills kept as made (build_implant 3) the rod grows. (A speck of implant high above
// widens the trim's grid to hold the fragment; being apart, it goes as well.)
TEST(TrimToBone, ARodOfFillToAFragmentGoes) {
  const SkullMesh bone = [&] {
    return merge(to_soup(gap_plates()), box({24.5, 9.5, 7.8}, {25.5, 10.5, 8.8}));
  }();
  const SkullMesh implant = merge(gap_implant(), box({17, 2, 11}, {18, 3, 12}));
  TrimToBoneParams wide;
  wide.bridge_mm = 3.0;
  TrimToBoneParams kept = wide;
  kept.thin_fills_removed = false;
  const TrimToBoneResult now = trim_to_bone(implant, bone, wide),
                         before = trim_to_bone(implant, bone, kept);
  ASSERT_TRUE(now.usable() && before.usable());
  auto top = [](const SkullMesh& m) { return highest(m, 2); };
  EXPECT_LE(top(now.mesh), 5.6) << "no rod up to the fragment";
  EXPECT_GE(top(before.mesh), 7.5) << "the case has the rod to remove";
  const QualityReport q = check_implant(now.mesh, &bone);
  EXPECT_LE(q.corner_reach_mm, 0.8);
}

// Plates 20 mm apart with an edge clearance of 2 mm (a material's), and 3 mm along the left cut
// face (a clearance zone, blending into the 2 mm beyond its radius): each wall lies its
// clearance off its cut face, to 0.2 mm, on the coarse grid.
TEST(TrimToBone, HoldsAWideClearanceAndAZoneOffObliqueCutFaces) {
  const Eigen::Matrix3d r =
      (Eigen::AngleAxisd(0.5, Eigen::Vector3d(1, 2, 3).normalized())).toRotationMatrix();
  const SkullMesh bone =
      turned(merge(box({0, 0, 0}, {20, 20, 5}), box({40, 0, 0}, {60, 20, 5})), r);
  const SkullMesh implant = turned(build_mesh(box({17, 2, 0}, {43, 18, 5.3})), r);
  TrimToBoneParams p;
  p.max_voxels = 1e5;
  p.clearance_mm = 2.0;
  p.zones = {{r * Eigen::Vector3d(20, 10, 2.5), 6.5, 3.0}};  // the left cut face
  const TrimToBoneResult t = trim_to_bone(implant, bone, p);
  ASSERT_TRUE(t.usable()) << t.message;
  const SurfaceLocator locator(bone);
  std::vector<double> left, right;
  for (auto vh : t.mesh.vertices()) {
    const Eigen::Vector3d q = r.transpose() * to_eigen(t.mesh.point(vh));
    if (q.z() < 1 || q.z() > 4 || q.y() < 4 || q.y() > 16) continue;
    const double d = locator.closest(r * q).distance;
    if (std::abs(q.x() - 23) < 0.5) left.push_back(d);
    if (std::abs(q.x() - 38) < 0.5) right.push_back(d);
  }
  ASSERT_GT(left.size(), 30u);
  ASSERT_GT(right.size(), 30u);
  for (double d : left) EXPECT_NEAR(d, 3.0, 0.2) << "the zone's clearance";
  for (double d : right) EXPECT_NEAR(d, 2.0, 0.2) << "the clearance";
  EXPECT_EQ(check_implant(t.mesh, &bone).penetration_mm3, 0.0);
  EXPECT_TRUE(report_mesh(t.mesh).watertight);
}

// The caller's locator of the whole skull (a plate far from the implant included) gives the
// fit, to the byte, that a locator of the skull's triangles near the implant gives: with the
// default clearance, a wide one, a zone, and for an implant with no bone near it.
TEST(TrimToBone, TheSkullsOwnLocatorGivesTheSameFit) {
  const Eigen::Matrix3d r =
      (Eigen::AngleAxisd(0.5, Eigen::Vector3d(1, 2, 3).normalized())).toRotationMatrix();
  TriangleSoup plates = box({0, 0, 0}, {20, 20, 5});
  const TriangleSoup right = box({40, 0, 0}, {60, 20, 5}), far = box({0, 80, 0}, {60, 100, 5});
  for (const TriangleSoup* b : {&right, &far}) {
    const int n = static_cast<int>(plates.vertices.size());
    plates.vertices.insert(plates.vertices.end(), b->vertices.begin(), b->vertices.end());
    for (auto t : b->triangles) plates.triangles.push_back({t[0] + n, t[1] + n, t[2] + n});
  }
  const SkullMesh bone = turned(build_mesh(plates), r);
  const SurfaceLocator whole(bone);
  const SkullMesh over_gap = turned(build_mesh(box({17, 2, 0}, {43, 18, 5.3})), r);
  const SkullMesh alone = turned(build_mesh(box({20, 40, 0}, {40, 60, 4})), r);
  TrimToBoneParams base;
  base.max_voxels = 2e5;
  TrimToBoneParams wide = base, zoned = base;
  wide.clearance_mm = 2.0;
  zoned.zones = {{r * Eigen::Vector3d(20, 10, 2.5), 6.5, 0.8}};
  for (const SkullMesh* implant : {&over_gap, &alone})
    for (const TrimToBoneParams* p : {&base, &wide, &zoned}) {
      SkullMesh with, without;
      const TrimToBoneResult a = trim_to_bone(*implant, bone, *p, with, &whole);
      const TrimToBoneResult b = trim_to_bone(*implant, bone, *p, without);
      ASSERT_TRUE(a.usable() && b.usable()) << a.message << b.message;
      EXPECT_EQ(a.volume_mm3, b.volume_mm3);
      const TriangleSoup sa = to_soup(with), sb = to_soup(without);
      EXPECT_EQ(sa.vertices, sb.vertices);
      EXPECT_EQ(sa.triangles, sb.triangles);
    }
}

// The fit says where its time went (bench's profile): each stage it ran once, in order, none
// negative, together no more than the whole; a clearance wider than a voxel adds its cut.
TEST(TrimToBone, ItsStagesAreTimedInTheOrderTheyRan) {
  const SkullMesh bone = merge(box({0, 0, 0}, {20, 20, 5}), box({40, 0, 0}, {60, 20, 5}));
  const SkullMesh implant = build_mesh(box({17, 2, 0}, {43, 18, 5.3}));
  TrimToBoneParams p;
  p.max_voxels = 1e5;
  const auto names = [](const TrimToBoneResult& t) {
    std::vector<std::string> n;
    double sum = 0.0;
    for (const auto& [stage, seconds] : t.stage_seconds) {
      n.push_back(stage);
      EXPECT_GE(seconds, 0.0) << stage;
      sum += seconds;
    }
    EXPECT_LE(sum, t.seconds + 1e-9);
    return n;
  };
  const TrimToBoneResult t = trim_to_bone(implant, bone, p);
  ASSERT_TRUE(t.usable()) << t.message;
  EXPECT_EQ(names(t),
            (std::vector<std::string>{"voxels", "opening", "cracks", "thin fills", "largest piece",
                                      "bone joined", "blur", "band", "cap", "meshing"}));
  p.clearance_mm = 2.0;
  const TrimToBoneResult wide = trim_to_bone(implant, bone, p);
  ASSERT_TRUE(wide.usable()) << wide.message;
  const std::vector<std::string> n = names(wide);
  ASSERT_GE(n.size(), 2u);
  EXPECT_EQ(n[1], "clearance cut");
}

// A large box on a fine grid is coarsened to the voxel budget; a small one keeps the spacing.
TEST(VoxelGrid, CoveringAtMostKeepsToTheVoxelBudget) {
  const Eigen::Vector3d lo(0, 0, 0), big(110, 90, 60), small(10, 10, 10);
  const VoxelGrid coarse = VoxelGrid::covering_at_most(lo, big, 0.25, 6e6, 4);
  EXPECT_GT(coarse.spacing, 0.25);
  EXPECT_LE(static_cast<double>(coarse.size()), 6e6);
  EXPECT_GE(static_cast<double>(coarse.size()), 6e6 * 0.8);
  const VoxelGrid fine = VoxelGrid::covering_at_most(lo, small, 0.25, 6e6, 4);
  EXPECT_EQ(fine.spacing, 0.25);
}

TEST(TrimToBone, AnImplantInsideTheBoneLeavesNothing) {
  const SkullMesh bone = build_mesh(box({0, 0, 0}, {20, 20, 5}));
  const SkullMesh implant = build_mesh(box({5, 5, 1}, {15, 15, 4}));
  const TrimToBoneResult r = trim_to_bone(implant, bone);
  EXPECT_EQ(r.status, TrimToBoneResult::Status::Empty);
  EXPECT_FALSE(r.message.empty());
  EXPECT_EQ(r.mesh.n_faces(), implant.n_faces()) << "the input is returned untouched";
}

}  // namespace
}  // namespace cranioplan
