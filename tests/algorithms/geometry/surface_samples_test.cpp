#include "cranioplan/algorithms/geometry/surface_samples.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "support/synthetic.h"

namespace cranioplan {
namespace {

// The Fibonacci lattice: unit directions, balanced (mean near the centre), and spread evenly
// (every direction's nearest neighbour about the lattice's spacing away, none much closer).
TEST(SurfaceSamples, TheFibonacciSphereSpreadsUnitDirectionsEvenly) {
  const int n = 2000;
  const std::vector<Eigen::Vector3d> d = fibonacci_sphere(n);
  ASSERT_EQ(d.size(), static_cast<size_t>(n));
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& v : d) {
    EXPECT_NEAR(v.norm(), 1.0, 1e-12);
    mean += v;
  }
  EXPECT_LT((mean / n).norm(), 1e-3);
  const double spacing = std::sqrt(4.0 * M_PI / n);  // radians per direction
  double closest = 10.0;
  for (int i = 0; i < n; i += 7)
    for (int j = 0; j < n; ++j)
      if (j != i) closest = std::min(closest, (d[i] - d[j]).norm());
  EXPECT_GT(closest, 0.5 * spacing);
}

// Vertex normals of a closed outward head point away from its centre; a subsample keeps the
// count asked for, the same samples every time, spread over the whole surface.
TEST(SurfaceSamples, NormalsPointOutAndSubsamplesAreDeterministic) {
  const SkullMesh head = test::make_symmetric_head(4);
  const SurfaceSamples all = all_vertex_samples(head);
  ASSERT_EQ(all.points.size(), head.n_vertices());
  int outward = 0;
  for (size_t i = 0; i < all.points.size(); ++i) {
    EXPECT_NEAR(all.normals[i].norm(), 1.0, 1e-9);
    outward += all.normals[i].dot(all.points[i]) > 0;
  }
  EXPECT_EQ(outward, static_cast<int>(all.points.size()));
  const SurfaceSamples a = subsample(all, 300), b = subsample(all, 300);
  ASSERT_EQ(a.points.size(), 300u);
  for (size_t i = 0; i < a.points.size(); ++i) EXPECT_EQ(a.points[i], b.points[i]);
  // Spread: samples on both sides of every axis.
  for (int k = 0; k < 3; ++k) {
    const auto [lo, hi] = std::minmax_element(
        a.points.begin(), a.points.end(),
        [k](const Eigen::Vector3d& p, const Eigen::Vector3d& q) { return p[k] < q[k]; });
    EXPECT_LT((*lo)[k], -30.0);
    EXPECT_GT((*hi)[k], 30.0);
  }
  EXPECT_EQ(subsample(all, 10 * all.points.size()).points.size(), all.points.size());
}

}  // namespace
}  // namespace cranioplan
