#include "cranioplan/algorithms/geometry/distance_transform.h"

#include <gtest/gtest.h>

#include <array>
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

// A mask of random balls and single voxels on a grid wider than the transform's tiles of 16
// lines, anisotropic so that axis mix-ups show.
std::vector<uint8_t> random_blobs(const VoxelGrid& g, unsigned seed) {
  std::vector<uint8_t> mask(g.size(), 0);
  std::mt19937 rng(seed);
  for (int n = 0; n < 14; ++n) {
    const int ci = int(rng() % g.dims[0]), cj = int(rng() % g.dims[1]), ck = int(rng() % g.dims[2]);
    const int r = 1 + int(rng() % 5);
    for (int k = 0; k < g.dims[2]; ++k)
      for (int j = 0; j < g.dims[1]; ++j)
        for (int i = 0; i < g.dims[0]; ++i)
          if ((i - ci) * (i - ci) + (j - cj) * (j - cj) + (k - ck) * (k - ck) <= r * r)
            mask[g.index(i, j, k)] = 1;
  }
  for (int n = 0; n < 40; ++n) mask[rng() % g.size()] = 1;  // specks
  return mask;
}

VoxelGrid test_grid(double spacing) {
  VoxelGrid g;
  g.spacing = spacing;
  g.dims = {37, 23, 19};
  return g;
}

// Every voxel's distance to the nearest voxel of `mask` by trying them all: the float of
// spacing·√(integer squared distance).
std::vector<float> brute_force_distances(const std::vector<uint8_t>& mask, const VoxelGrid& g) {
  std::vector<std::array<int, 3>> marked;
  for (int k = 0; k < g.dims[2]; ++k)
    for (int j = 0; j < g.dims[1]; ++j)
      for (int i = 0; i < g.dims[0]; ++i)
        if (mask[g.index(i, j, k)]) marked.push_back({i, j, k});
  std::vector<float> d(g.size());
  for (int k = 0; k < g.dims[2]; ++k)
    for (int j = 0; j < g.dims[1]; ++j)
      for (int i = 0; i < g.dims[0]; ++i) {
        long long best = -1;
        for (const auto& m : marked) {
          const long long d2 =
              (i - m[0]) * (i - m[0]) + (j - m[1]) * (j - m[1]) + (k - m[2]) * (k - m[2]);
          if (best < 0 || d2 < best) best = d2;
        }
        d[g.index(i, j, k)] = static_cast<float>(g.spacing * std::sqrt(static_cast<double>(best)));
      }
  return d;
}

// One step of 6-neighbour dilation.
std::vector<uint8_t> dilate(const std::vector<uint8_t>& in, const VoxelGrid& g) {
  std::vector<uint8_t> out(in);
  for (int k = 0; k < g.dims[2]; ++k)
    for (int j = 0; j < g.dims[1]; ++j)
      for (int i = 0; i < g.dims[0]; ++i) {
        const int nb[6][3] = {{i - 1, j, k}, {i + 1, j, k}, {i, j - 1, k},
                              {i, j + 1, k}, {i, j, k - 1}, {i, j, k + 1}};
        for (const auto& n : nb)
          if (n[0] >= 0 && n[1] >= 0 && n[2] >= 0 && n[0] < g.dims[0] && n[1] < g.dims[1] &&
              n[2] < g.dims[2] && in[g.index(n[0], n[1], n[2])])
            out[g.index(i, j, k)] = 1;
      }
  return out;
}

// The bounded transform gives the whole one's float within the bound and more beyond it;
// returns how many voxels it left infinite.
size_t expect_bounded_agrees(const std::vector<uint8_t>& mask, const VoxelGrid& g,
                             const std::vector<float>& full, double bound) {
  const std::vector<float> bounded = distance_to_mask(mask, g, bound);
  size_t cut = 0;
  for (size_t c = 0; c < g.size(); ++c) {
    if (full[c] <= bound) {
      EXPECT_EQ(bounded[c], full[c]) << c << " within " << bound;
    } else {
      EXPECT_GT(bounded[c], bound) << c << " within " << bound;
      cut += std::isinf(bounded[c]);
    }
  }
  return cut;
}

// Every value is the float of spacing·√(integer squared distance), as brute force gives it.
TEST(DistanceTransform, IsExactOnGridsWiderThanItsTiles) {
  const VoxelGrid g = test_grid(0.25);
  const std::vector<uint8_t> mask = random_blobs(g, 5);
  EXPECT_EQ(distance_to_mask(mask, g), brute_force_distances(mask, g));
}

// The sweeps give what `steps` 6-neighbour dilations give, of blobs and of three single voxels
// (which grow for all of the 20 steps tried).
TEST(DistanceTransform, WithinStepsIsRepeatedDilation) {
  const VoxelGrid g = test_grid(0.25);
  std::vector<uint8_t> specks(g.size(), 0);
  specks[g.index(0, 0, 0)] = specks[g.index(30, 20, 3)] = specks[g.index(9, 15, 17)] = 1;
  for (const std::vector<uint8_t>& mask : {random_blobs(g, 7), specks}) {
    std::vector<uint8_t> grown = mask;
    for (int steps = 0; steps <= 20; ++steps) {
      EXPECT_EQ(within_steps(mask, g, steps), grown) << steps << " steps";
      grown = dilate(grown, g);
    }
  }
  EXPECT_EQ(within_steps(std::vector<uint8_t>(g.size(), 0), g, 3),
            std::vector<uint8_t>(g.size(), 0));
}

// Bounded to a distance, the transform gives the whole transform's float wherever that is at
// most the bound and a larger value elsewhere, so every test against the bound agrees; the
// opening by a ball, which uses it, is the union of the balls the whole transforms find.
TEST(DistanceTransform, BoundedAgreesWithTheWholeTransformUpToItsBound) {
  for (const double spacing : {0.25, 0.4}) {
    SCOPED_TRACE(spacing);
    const VoxelGrid g = test_grid(spacing);
    const std::vector<uint8_t> mask = random_blobs(g, 17);
    const std::vector<float> full = distance_to_mask(mask, g);
    size_t cut = 0;
    for (const double bound : {0.0, 0.3, 0.75, 1.0, 1.6, 100.0}) {
      cut += expect_bounded_agrees(mask, g, full, bound);
      size_t near = 0, far = 0;
      for (size_t c = 0; c < g.size(); ++c) (full[c] <= bound ? near : far) += 1;
      EXPECT_GT(near, 0u);
      if (bound < 10.0) {
        EXPECT_GT(far, 0u);
      }
    }
    EXPECT_GT(cut, 0u) << "the windows were used";
    EXPECT_TRUE(std::isinf(distance_to_mask(std::vector<uint8_t>(g.size(), 0), g, 1.0)[0]));
    for (const double radius : {0.5, 0.9}) {
      const std::vector<uint8_t> centres =
          ball_centres(depth_in_mask(mask, g), g, radius);  // the whole transforms
      const std::vector<float> to_centre = distance_to_mask(centres, g);
      const std::vector<uint8_t> opened = open_by_ball(mask, g, radius);
      EXPECT_EQ(ball_centres(mask, g, radius), centres) << radius;
      size_t removed = 0;
      for (size_t c = 0; c < g.size(); ++c) {
        ASSERT_EQ(opened[c] != 0, mask[c] && to_centre[c] <= radius + 0.5 * spacing) << c;
        removed += mask[c] && !opened[c];
      }
      EXPECT_GT(removed, 0u);
    }
  }
}

// Blobs, and two slabs of whole rows along x (k = 8, 9, and j = 4 for every k): a mask with
// rows all inside it, rows far from it and rows through its surface, and its complement (the
// outside a depth is measured to).
std::vector<uint8_t> slabs_and_blobs(const VoxelGrid& g) {
  std::vector<uint8_t> mask = random_blobs(g, 23);
  for (int k = 0; k < g.dims[2]; ++k)
    for (int j = 0; j < g.dims[1]; ++j)
      for (int i = 0; i < g.dims[0]; ++i)
        if (k == 8 || k == 9 || j == 4) mask[g.index(i, j, k)] = 1;
  return mask;
}

// The passes skip the rows that lie all inside the mask or far from it: every value is still
// brute force's float, the bounded transform the whole one's, the steps the dilations'.
TEST(DistanceTransform, RowsAllInsideOrFarFromTheMaskAreExact) {
  const VoxelGrid g = test_grid(0.25);
  std::vector<uint8_t> slabs = slabs_and_blobs(g), outside(slabs.size());
  for (size_t c = 0; c < slabs.size(); ++c) outside[c] = !slabs[c];
  for (const std::vector<uint8_t>& mask : {slabs, outside}) {
    const std::vector<float> full = distance_to_mask(mask, g);
    EXPECT_EQ(full, brute_force_distances(mask, g));
    size_t cut = 0;
    for (const double bound : {0.3, 0.75, 1.6}) cut += expect_bounded_agrees(mask, g, full, bound);
    EXPECT_GT(cut, 0u) << "the windows were used";
    std::vector<uint8_t> grown = mask;
    for (int steps = 0; steps <= 8; ++steps) {
      EXPECT_EQ(within_steps(mask, g, steps), grown) << steps << " steps";
      grown = dilate(grown, g);
    }
  }
}

// The local tests agree with the whole-grid transforms on every voxel, at several distances
// and spacings (the fit to the bone asks them of the few voxels a bridging fill adds).
TEST(DistanceTransform, LocalTestsAgreeWithTheWholeGrid) {
  for (const double spacing : {0.25, 0.4, 1.0}) {
    SCOPED_TRACE(spacing);
    const VoxelGrid g = test_grid(spacing);
    const std::vector<uint8_t> mask = random_blobs(g, 11);
    const std::vector<float> d = distance_to_mask(mask, g);
    for (const float mm : {0.3f, 1.0f, 1.7f}) {
      size_t far = 0;
      const LocalDistance local(mask, g, mm);
      for (size_t c = 0; c < g.size(); ++c) {
        ASSERT_EQ(local.farther(c), d[c] > mm) << c << " at " << mm << " mm";
        far += d[c] > mm;
      }
      EXPECT_GT(far, 0u);
      EXPECT_LT(far, g.size());
    }
    for (const double radius : {0.5, 0.9}) {
      const std::vector<uint8_t> opened = open_by_ball(mask, g, radius);
      LocalOpening local(mask, g, radius);
      size_t kept = 0, removed = 0;
      for (size_t c = 0; c < g.size(); ++c) {
        if (!mask[c]) continue;
        ASSERT_EQ(local.contains(c), opened[c] != 0) << c << " radius " << radius;
        kept += opened[c] != 0;
        removed += opened[c] == 0;
      }
      if (spacing < 0.5) {
        EXPECT_GT(kept, 0u);
        EXPECT_GT(removed, 0u);
      }
    }
  }
}

}  // namespace
}  // namespace cranioplan
