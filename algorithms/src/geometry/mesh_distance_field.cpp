#include "cranioplan/algorithms/geometry/mesh_distance_field.h"

#include <algorithm>
#include <cmath>

#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/geometry/voxelize_mesh.h"
#include "cranioplan/model/parallel.h"

namespace cranioplan {

double smooth_min(double a, double b, double k) {
  const double w = std::max(k - std::abs(a - b), 0.0) / k;
  return std::min(a, b) - 0.25 * w * w * k;
}

std::vector<float> signed_distance_near_surface(const SurfaceLocator& locator,
                                                const std::vector<uint8_t>& solid,
                                                const VoxelGrid& g, float far_mm) {
  std::vector<float> field(solid.size());
  for (size_t c = 0; c < solid.size(); ++c) field[c] = solid[c] ? far_mm : -far_mm;
  const int nx = g.dims[0], ny = g.dims[1], nz = g.dims[2];
  // Near the surface: within two voxels (along each axis in turn) of a voxel whose neighbour
  // along an axis is on the other side.
  std::vector<uint8_t> band(solid.size(), 0);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const size_t c = g.index(i, j, k);
        band[c] = (i + 1 < nx && solid[g.index(i + 1, j, k)] != solid[c]) ||
                  (j + 1 < ny && solid[g.index(i, j + 1, k)] != solid[c]) ||
                  (k + 1 < nz && solid[g.index(i, j, k + 1)] != solid[c]);
      }
  const size_t step[3] = {1, static_cast<size_t>(nx), static_cast<size_t>(nx) * ny};
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<uint8_t> grown = band;
    for (int k = 0; k < nz; ++k)
      for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
          const size_t c = g.index(i, j, k);
          if (!band[c]) continue;
          const int at = axis == 0 ? i : axis == 1 ? j : k, n = g.dims[axis];
          for (int d = -2; d <= 3; ++d)  // the pair (c, c+1) straddles: both sides' reach
            if (at + d >= 0 && at + d < n)
              grown[static_cast<size_t>(static_cast<long long>(c) +
                                        d * static_cast<long long>(step[axis]))] = 1;
        }
    band = std::move(grown);
  }
  parallel_for(solid.size(), [&](size_t begin, size_t end) {
    for (size_t c = begin; c < end; ++c) {
      if (!band[c]) continue;
      const int i = static_cast<int>(c % nx), j = static_cast<int>((c / nx) % ny),
                k = static_cast<int>(c / (static_cast<size_t>(nx) * ny));
      field[c] =
          static_cast<float>(locator.closest(g.center(i, j, k)).distance * (solid[c] ? 1.0 : -1.0));
    }
  });
  return field;
}

}  // namespace cranioplan
