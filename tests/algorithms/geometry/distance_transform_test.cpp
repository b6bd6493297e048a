#include "cranioplan/algorithms/geometry/distance_transform.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace cranioplan {
namespace {

// Exact: against brute force over every marked voxel of a random sparse mask on an anisotropic
// box of a grid (dims differ per axis so that axis mix-ups show).
TEST(DistanceTransform, AgreesWithBruteForce) {
  VoxelGrid g;
  g.spacing = 0.3;
  g.dims = {13, 7, 10};
  std::vector<uint8_t> mask(g.size(), 0);
  std::mt19937 rng(3);
  std::vector<std::array<int, 3>> marked;
  for (int n = 0; n < 12; ++n) {
    const std::array<int, 3> v = {int(rng() % 13), int(rng() % 7), int(rng() % 10)};
    mask[g.index(v[0], v[1], v[2])] = 1;
    marked.push_back(v);
  }
  const std::vector<float> d = distance_to_mask(mask, g);
  for (int k = 0; k < 10; ++k)
    for (int j = 0; j < 7; ++j)
      for (int i = 0; i < 13; ++i) {
        double best = 1e30;
        for (const auto& m : marked)
          best = std::min(
              best, g.spacing * std::sqrt(double((i - m[0]) * (i - m[0]) + (j - m[1]) * (j - m[1]) +
                                                 (k - m[2]) * (k - m[2]))));
        EXPECT_NEAR(d[g.index(i, j, k)], best, 1e-5);
      }
  EXPECT_TRUE(std::isinf(distance_to_mask(std::vector<uint8_t>(g.size(), 0), g)[0]));
}

}  // namespace
}  // namespace cranioplan
