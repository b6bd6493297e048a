#include "cranioplan/algorithms/mesh_report.h"

#include <gtest/gtest.h>

#include "support/synthetic.h"

namespace cranioplan {
namespace {

TEST(MeshReport, ClosedHeadIsWatertightWithOnePiece) {
  const MeshReport r = report_mesh(test::make_symmetric_head(3));
  EXPECT_TRUE(r.watertight);
  EXPECT_EQ(r.pieces, 1);
  EXPECT_EQ(r.boundary_edges, 0);
  EXPECT_GT(r.volume_mm3, 0);
  EXPECT_EQ(r.triangles, 1280);
}

TEST(MeshReport, HoleGivesBoundaryEdgesAndCubeHasKnownAreaAndVolume) {
  EXPECT_FALSE(
      report_mesh(test::cut_hole(test::make_symmetric_head(3), {70, 0, 0}, 20)).watertight);
  TriangleSoup cube;
  for (int i = 0; i < 8; ++i)
    cube.vertices.emplace_back(i & 1 ? 2 : 0, i & 2 ? 2 : 0, i & 4 ? 2 : 0);
  cube.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                    {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  const MeshReport r = report_mesh(build_mesh(cube));
  EXPECT_NEAR(r.area_mm2, 24.0, 1e-12);
  EXPECT_NEAR(r.volume_mm3, 8.0, 1e-12);
  EXPECT_TRUE(r.watertight);
  EXPECT_EQ(r.bbox_max, Eigen::Vector3d(2, 2, 2));
}

TEST(MeshReport, NonManifoldEdgeIsCounted) {
  TriangleSoup s;
  s.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}};
  s.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};  // three triangles on edge 0-1
  const MeshReport r = report_mesh(build_mesh(s));
  EXPECT_EQ(r.nonmanifold_edges, 1);
  EXPECT_FALSE(r.watertight);
}

}  // namespace
}  // namespace cranioplan
