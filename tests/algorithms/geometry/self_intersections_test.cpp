#include "cranioplan/algorithms/geometry/self_intersections.h"

#include <gtest/gtest.h>

#include "support/synthetic.h"

namespace cranioplan {
namespace {

TEST(SelfIntersections, CrossingTrianglesAreCountedAndAClosedSurfaceHasNone) {
  TriangleSoup s;
  s.vertices = {{0, 0, 0}, {4, 0, 0}, {0, 4, 0}, {1, 1, -1}, {1, 1, 1}, {3, 3, 0.5}};
  s.triangles = {{0, 1, 2}, {3, 4, 5}};  // the second pierces the first
  EXPECT_EQ(count_self_intersections(build_mesh(s)), 1);
  EXPECT_EQ(count_self_intersections(test::make_symmetric_head(3)), 0);
}

// Triangles that share an edge or a corner touch but do not cross: a closed box has none, and
// a box through another box crosses it along four of its faces.
TEST(SelfIntersections, NeighboursTouchWithoutCrossingAndTwoBoxesCross) {
  const SkullMesh box = build_mesh(test::box_soup({0, 0, 0}, {10, 10, 10}));
  EXPECT_EQ(count_self_intersections(box), 0);
  TriangleSoup two = test::box_soup({0, 0, 0}, {10, 10, 10});
  const TriangleSoup bar = test::box_soup({-5, 3, 3}, {15, 7, 7});
  const int n = static_cast<int>(two.vertices.size());
  two.vertices.insert(two.vertices.end(), bar.vertices.begin(), bar.vertices.end());
  for (Eigen::Vector3i t : bar.triangles) two.triangles.push_back(t + Eigen::Vector3i::Constant(n));
  EXPECT_GT(count_self_intersections(build_mesh(two)), 0);
}

}  // namespace
}  // namespace cranioplan
