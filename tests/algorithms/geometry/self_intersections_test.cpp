#include "cranioplan/algorithms/geometry/self_intersections.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "cranioplan/model/parallel.h"
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

// Random triangles of many sizes in a box, most pairs apart, many crossing: the count is the
// brute-force count over every pair, on one thread and on two.
TEST(SelfIntersections, AgreesWithEveryPairTestedOnRandomTriangles) {
  auto crosses = [](const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& a,
                    const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
    const Eigen::Vector3d n = (b - a).cross(c - a);
    const double sp = n.dot(p - a), sq = n.dot(q - a);
    if ((sp > 0) == (sq > 0) || sp == 0 || sq == 0) return false;
    const Eigen::Vector3d x = p + (q - p) * (sp / (sp - sq));
    const double u = n.dot((b - a).cross(x - a)), v = n.dot((c - b).cross(x - b)),
                 w = n.dot((a - c).cross(x - c));
    return u > 0 && v > 0 && w > 0;
  };
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> at(0.0, 20.0), size(0.2, 4.0), unit(-1.0, 1.0);
  TriangleSoup soup;
  for (int t = 0; t < 600; ++t) {
    const Eigen::Vector3d c(at(rng), at(rng), at(rng));
    const double r = size(rng);
    const int first = static_cast<int>(soup.vertices.size());
    for (int k = 0; k < 3; ++k)
      soup.vertices.push_back(c + r * Eigen::Vector3d(unit(rng), unit(rng), unit(rng)));
    soup.triangles.emplace_back(first, first + 1, first + 2);
  }
  long long expected = 0;
  const auto& V = soup.vertices;
  for (size_t i = 0; i < soup.triangles.size(); ++i)
    for (size_t j = i + 1; j < soup.triangles.size(); ++j) {
      const auto &a = soup.triangles[i], &b = soup.triangles[j];
      bool cross = false;
      for (int e = 0; e < 3; ++e)
        cross = cross || crosses(V[a[e]], V[a[(e + 1) % 3]], V[b[0]], V[b[1]], V[b[2]]) ||
                crosses(V[b[e]], V[b[(e + 1) % 3]], V[a[0]], V[a[1]], V[a[2]]);
      expected += cross;
    }
  ASSERT_GT(expected, 20);
  const SkullMesh mesh = build_mesh(soup);
  set_thread_count(1);
  const long long one = count_self_intersections(mesh);
  set_thread_count(2);
  const long long two = count_self_intersections(mesh);
  set_thread_count(0);
  EXPECT_EQ(one, expected);
  EXPECT_EQ(two, expected);
}

}  // namespace
}  // namespace cranioplan
