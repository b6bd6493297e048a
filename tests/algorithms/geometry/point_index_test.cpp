#include "cranioplan/algorithms/geometry/point_index.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace cranioplan {
namespace {

std::vector<Eigen::Vector3d> random_points(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-50.0, 50.0);
  std::vector<Eigen::Vector3d> pts;
  for (int i = 0; i < n; ++i) pts.emplace_back(u(rng), u(rng), u(rng));
  return pts;
}

// The k-d tree answers as a brute-force search does: the nearest point and its squared
// distance, and every point within a radius (and no other).
TEST(PointIndex, AgreesWithBruteForce) {
  const std::vector<Eigen::Vector3d> pts = random_points(2000, 3);
  const PointIndex index(pts);
  EXPECT_EQ(index.size(), pts.size());
  for (const Eigen::Vector3d& q : random_points(200, 11)) {
    double d2 = 0.0;
    const int got = index.nearest(q, &d2);
    double best = std::numeric_limits<double>::infinity();
    for (const auto& p : pts) best = std::min(best, (p - q).squaredNorm());
    EXPECT_NEAR(d2, best, 1e-9);
    EXPECT_NEAR((pts[got] - q).squaredNorm(), best, 1e-9);
    std::vector<int> within = index.within_radius(q, 12.0), brute;
    for (int i = 0; i < static_cast<int>(pts.size()); ++i)
      if ((pts[i] - q).norm() <= 12.0) brute.push_back(i);
    std::sort(within.begin(), within.end());
    EXPECT_EQ(within, brute);
  }
}

// Thinning keeps points at least the spacing apart, earlier points first, and every dropped
// point lies within the spacing of a kept one.
TEST(PointIndex, ThinningKeepsEarlierPointsAtTheSpacing) {
  const std::vector<Eigen::Vector3d> pts = random_points(1500, 5);
  const std::vector<size_t> kept = thin_points(pts, 8.0);
  ASSERT_FALSE(kept.empty());
  EXPECT_EQ(kept.front(), 0u) << "the first point is always kept";
  for (size_t a = 0; a < kept.size(); ++a)
    for (size_t b = a + 1; b < kept.size(); ++b)
      EXPECT_GE((pts[kept[a]] - pts[kept[b]]).norm(), 8.0 - 1e-9);
  std::vector<char> is_kept(pts.size(), 0);
  for (size_t k : kept) is_kept[k] = 1;
  for (size_t i = 0; i < pts.size(); ++i) {
    if (is_kept[i]) continue;
    double nearest = std::numeric_limits<double>::infinity();
    for (size_t k : kept) nearest = std::min(nearest, (pts[k] - pts[i]).norm());
    EXPECT_LT(nearest, 8.0);
  }
}

}  // namespace
}  // namespace cranioplan
