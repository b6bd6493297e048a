#include "cranioplan/algorithms/io/extract_bone_surface.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "cranioplan/algorithms/geometry/self_intersections.h"
#include "cranioplan/algorithms/geometry/voxelize_mesh.h"
#include "cranioplan/algorithms/io/mesh_report.h"
#include "support/synthetic.h"

namespace cranioplan {
namespace {

TEST(ExtractBoneSurface, BallGivesClosedOutwardSurfaceOfTheRightVolume) {
  const Volume v = test::make_ball_volume({5, 6, 7}, 12.0, 40, 0.8, true);
  const auto r = extract_bone_surface(v);
  ASSERT_TRUE(r.usable()) << r.message;
  EXPECT_EQ(r.threshold_used, 300.0);
  const MeshReport rep = report_mesh(r.mesh);
  EXPECT_TRUE(rep.watertight);
  EXPECT_EQ(rep.pieces, 1);
  EXPECT_NEAR(rep.volume_mm3, 4.0 / 3.0 * M_PI * 12 * 12 * 12, 0.05 * 7238.2);
}

// Whole-numbered samples are meshed as small integers (doubled, with the threshold) and other
// samples as floats; doubling is exact, so both give the same surface to the last bit. One
// sample far below every other, away from the bone, sends the same data down the other path
// (its double no longer fits): the surface must not change.
TEST(ExtractBoneSurface, SmallIntegerSamplesGiveTheSurfaceOfTheirFloats) {
  for (const bool ct : {true, false}) {
    Volume v = test::make_ball_volume({1, 2, 3}, 9.0, 30, 0.9, ct);
    if (ct)  // values that vary across the surface, whole numbers of HU
      for (int k = 0; k < 30; ++k)
        for (int j = 0; j < 30; ++j)
          for (int i = 0; i < 30; ++i) {
            const double r = (v.world(Eigen::Vector3d(i, j, k)) - Eigen::Vector3d(1, 2, 3)).norm();
            v.data[v.index(i, j, k)] = static_cast<float>(
                std::clamp(std::round(1000.0 - 400.0 * (r - 9.0)), -1000.0, 2000.0));
          }
    for (const float low : {-100.0f, -40000.0f}) {
      if (ct && low == -100.0f) continue;  // a CT's samples already lie below −100
      Volume other = v;
      other.data[0] = low;  // a corner, far from the ball
      ExtractBoneSurfaceParams params;
      params.threshold = v.default_threshold() + 0.25;  // between samples, never on one
      const SkullMesh a = extract_bone_surface(v, params).mesh;
      const SkullMesh b = extract_bone_surface(other, params).mesh;
      ASSERT_EQ(a.n_vertices(), b.n_vertices()) << ct << " " << low;
      ASSERT_GT(a.n_faces(), 500u);
      for (auto vh : a.vertices()) ASSERT_EQ(a.point(vh), b.point(vh)) << ct << " " << low;
      const TriangleSoup sa = to_soup(a), sb = to_soup(b);
      EXPECT_EQ(sa.triangles, sb.triangles);
    }
  }
}

TEST(ExtractBoneSurface, BallTouchingTheScanEdgeIsStillClosed) {
  Volume v = test::make_ball_volume({0, 0, 0}, 10.0, 20, 1.0, false);  // 20 mm grid, ball 20 mm
  v.origin.x() += 4.0;  // move the grid so the ball is cut by the first slab
  const auto r = extract_bone_surface(v);
  EXPECT_TRUE(report_mesh(r.mesh).watertight);
}

TEST(ExtractBoneSurface, LargestPieceOrAllPiecesAboveASize) {
  Volume v = test::make_ball_volume({0, 0, 0}, 4.0, 40, 1.0, false);
  for (int k = 0; k < 40; ++k)
    for (int j = 0; j < 40; ++j)
      for (int i = 0; i < 40; ++i)
        if ((v.world(Eigen::Vector3d(i, j, k)) - Eigen::Vector3d(10, 10, 10)).norm() < 7)
          v.data[v.index(i, j, k)] = 1;
  const auto largest = extract_bone_surface(v);
  EXPECT_EQ(largest.pieces_found, 2);
  EXPECT_EQ(report_mesh(largest.mesh).pieces, 1);
  ExtractBoneSurfaceParams all;
  all.largest_piece_only = false;
  all.min_piece_triangles = 10;
  EXPECT_EQ(report_mesh(extract_bone_surface(v, all).mesh).pieces, 2);
}

TEST(ExtractBoneSurface, DecimatesToTarget) {
  const Volume v = test::make_ball_volume({0, 0, 0}, 15.0, 40, 1.0, false);
  ExtractBoneSurfaceParams p;
  p.target_triangles = 1000;
  const auto r = extract_bone_surface(v, p);
  EXPECT_GT(r.triangles_before_decimation, 4000);
  EXPECT_NEAR(static_cast<double>(r.mesh.n_faces()), 1000.0, 100.0);
  EXPECT_GT(signed_volume(r.mesh), 0.0);
}

TEST(ExtractBoneSurface, ThresholdOutsideTheDataGivesAStatusNotAnException) {
  const Volume v = test::make_ball_volume({0, 0, 0}, 5.0, 16, 1.0, true);
  ExtractBoneSurfaceParams p;
  p.threshold = 5000;
  const auto r = extract_bone_surface(v, p);
  EXPECT_FALSE(r.usable());
  EXPECT_NE(r.message.find("no surface"), std::string::npos);
}

// A solid whose surface passes within a millionth of a voxel of grid points (a slanted face
// through a lattice of them, as a tab's or a drilled implant's distance field may): the vertices
// of the edges meeting at such a point do not fall together into triangles without area.
TEST(ExtractBoneSurface, ASurfaceThroughGridPointsGetsNoSliverTriangles) {
  VoxelGrid g;
  g.spacing = 0.2;
  g.dims = {24, 24, 24};
  const Eigen::Vector3d n = Eigen::Vector3d(1, 1, 1).normalized();
  const Eigen::Vector3d centre = g.center(12, 12, 12);
  // The half-space below the plane x + y + z = 36 (in voxels), a millionth of a voxel above it,
  // cut to a ball so that the solid is closed.
  const double offset = n.dot(g.center(12, 12, 12)) + 1e-6 * g.spacing;
  std::vector<float> distance(g.size());
  for (int k = 0; k < g.dims[2]; ++k)
    for (int j = 0; j < g.dims[1]; ++j)
      for (int i = 0; i < g.dims[0]; ++i) {
        const Eigen::Vector3d p = g.center(i, j, k);
        distance[g.index(i, j, k)] =
            static_cast<float>(std::min(offset - n.dot(p), 2.0 - (p - centre).norm()));
      }
  auto shortest_edge = [](const SkullMesh& mesh) {
    double shortest = std::numeric_limits<double>::infinity();
    for (const auto e : mesh.edges())
      shortest = std::min(shortest, static_cast<double>(mesh.calc_edge_length(e)));
    return shortest;
  };
  const ExtractBoneSurfaceResult r = surface_of_signed_distance(distance, g);
  ASSERT_TRUE(r.usable()) << r.message;
  EXPECT_TRUE(report_mesh(r.mesh).watertight);
  EXPECT_EQ(count_self_intersections(r.mesh), 0);
  EXPECT_GT(shortest_edge(r.mesh), 1e-4 * g.spacing);
  // Without the gap (plans saved before it are meshed so), the slivers are there.
  const ExtractBoneSurfaceResult old = surface_of_signed_distance(std::move(distance), g, false);
  ASSERT_TRUE(old.usable()) << old.message;
  EXPECT_LT(shortest_edge(old.mesh), 1e-4 * g.spacing);
}

}  // namespace
}  // namespace cranioplan
