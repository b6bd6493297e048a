#include "cranioplan/algorithms/geometry/distance_transform.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "cranioplan/algorithms/geometry/parallel.h"

namespace cranioplan {

namespace {

constexpr double kFar = 1e30;

// d[q] = min over p of (q − p)² + f[p], for one line of n samples (squared distances in voxel
// units). v, z: scratch of n and n + 1 entries.
void lower_envelope(const double* f, double* d, int n, std::vector<int>& v,
                    std::vector<double>& z) {
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (f[q] >= kFar) continue;
    double s = 0.0;
    while (k >= 0) {
      const int p = v[k];
      s = ((f[q] + double(q) * q) - (f[p] + double(p) * p)) / (2.0 * (q - p));
      if (s > z[k]) break;
      --k;
    }
    ++k;
    v[k] = q;
    z[k] = k == 0 ? -kFar : s;
    z[k + 1] = kFar;
  }
  if (k < 0) {
    std::fill(d, d + n, kFar);
    return;
  }
  int j = 0;
  for (int q = 0; q < n; ++q) {
    while (z[j + 1] < q) ++j;
    const double dq = q - v[j];
    d[q] = dq * dq + f[v[j]];
  }
}

}  // namespace

std::vector<float> distance_to_mask(const std::vector<uint8_t>& mask, const VoxelGrid& grid) {
  const int dims[3] = {grid.dims[0], grid.dims[1], grid.dims[2]};
  std::vector<double> sq(mask.size());
  for (size_t c = 0; c < mask.size(); ++c) sq[c] = mask[c] ? 0.0 : kFar;
  const int longest = std::max({dims[0], dims[1], dims[2]});
  const size_t stride[3] = {1, static_cast<size_t>(dims[0]),
                            static_cast<size_t>(dims[0]) * dims[1]};
  for (int axis = 0; axis < 3; ++axis) {
    const int a = (axis + 1) % 3, b = (axis + 2) % 3;
    // The lines along the axis are independent: each thread takes a range of them.
    parallel_for(
        static_cast<size_t>(dims[b]),
        [&](size_t first, size_t last) {
          std::vector<double> line(longest), out(longest);
          std::vector<int> v(longest);
          std::vector<double> z(longest + 1);
          for (size_t j = first; j < last; ++j)
            for (int i = 0; i < dims[a]; ++i) {
              const size_t base = i * stride[a] + j * stride[b];
              for (int q = 0; q < dims[axis]; ++q) line[q] = sq[base + q * stride[axis]];
              lower_envelope(line.data(), out.data(), dims[axis], v, z);
              for (int q = 0; q < dims[axis]; ++q) sq[base + q * stride[axis]] = out[q];
            }
        },
        4);
  }
  std::vector<float> d(mask.size());
  for (size_t c = 0; c < mask.size(); ++c)
    d[c] = sq[c] >= kFar ? std::numeric_limits<float>::infinity()
                         : static_cast<float>(grid.spacing * std::sqrt(sq[c]));
  return d;
}

std::vector<float> depth_in_mask(const std::vector<uint8_t>& mask, const VoxelGrid& grid) {
  std::vector<uint8_t> out(mask.size());
  for (size_t c = 0; c < mask.size(); ++c) out[c] = !mask[c];
  // The grid's outermost layer stands for the outside beyond it.
  const int nx = grid.dims[0], ny = grid.dims[1], nz = grid.dims[2];
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        if (i == 0 || j == 0 || k == 0 || i == nx - 1 || j == ny - 1 || k == nz - 1)
          out[grid.index(i, j, k)] = 1;
  return distance_to_mask(out, grid);
}

std::vector<uint8_t> ball_centres(const std::vector<float>& depth, const VoxelGrid& grid,
                                  double radius) {
  const double need = radius + 0.5 * grid.spacing;
  std::vector<uint8_t> out(depth.size());
  for (size_t c = 0; c < depth.size(); ++c) out[c] = depth[c] >= need;
  return out;
}

std::vector<uint8_t> ball_centres(const std::vector<uint8_t>& mask, const VoxelGrid& grid,
                                  double radius) {
  return ball_centres(depth_in_mask(mask, grid), grid, radius);
}

std::vector<uint8_t> open_by_ball(const std::vector<uint8_t>& mask, const VoxelGrid& grid,
                                  double radius) {
  const std::vector<float> to_centre = distance_to_mask(ball_centres(mask, grid, radius), grid);
  std::vector<uint8_t> out(mask.size());
  for (size_t c = 0; c < mask.size(); ++c)
    out[c] = mask[c] && to_centre[c] <= radius + 0.5 * grid.spacing;
  return out;
}

}  // namespace cranioplan
