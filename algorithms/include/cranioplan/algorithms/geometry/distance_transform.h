#pragma once
// Exact Euclidean distance transform of a voxel mask (Felzenszwalb & Huttenlocher's lower
// envelope of parabolas, one axis at a time): the ground of thickness and clearance measures.
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "cranioplan/algorithms/geometry/voxelize_mesh.h"

namespace cranioplan {

/// For every voxel, the distance (mm) from its centre to the centre of the nearest voxel whose
/// mask value is non-zero: 0 on the mask itself, +infinity everywhere when the mask is empty.
std::vector<float> distance_to_mask(const std::vector<uint8_t>& mask, const VoxelGrid& grid);
/// The same where it is at most `within_mm` (the same floats); elsewhere a value larger than
/// `within_mm` (+infinity, or the distance itself). Tests of a distance against a limit of at
/// most `within_mm` give what they give on the whole transform, at a fraction of its cost when
/// the limit is a few voxels (windows of that many voxels along y and z instead of envelopes).
std::vector<float> distance_to_mask(const std::vector<uint8_t>& mask, const VoxelGrid& grid,
                                    double within_mm);

/// For every voxel of `mask`, the distance (mm) from its centre to the centre of the nearest
/// voxel outside it; 0 outside. The grid's outermost layer counts as outside (it stands for what
/// lies beyond the grid). The surface lies between the two centres, so twice the depth bounds
/// the diameter of the largest ball inside the mask around that voxel from above.
std::vector<float> depth_in_mask(const std::vector<uint8_t>& mask, const VoxelGrid& grid);

/// The voxels of `mask` that are centres of balls of `radius` mm inside it: those at least
/// `radius` from the outside (a voxel centre lies, on average, half a voxel nearer the surface
/// than the nearest outside voxel centre, which is allowed for). Voxels beyond the grid count as
/// outside.
std::vector<uint8_t> ball_centres(const std::vector<uint8_t>& mask, const VoxelGrid& grid,
                                  double radius);
/// The same from the mask's depth_in_mask(), when the caller needs the depth too.
std::vector<uint8_t> ball_centres(const std::vector<float>& depth, const VoxelGrid& grid,
                                  double radius);

/// Morphological opening by a ball of `radius` mm: the union of the balls that fit inside the
/// mask. What it removes is thinner than 2·radius.
std::vector<uint8_t> open_by_ball(const std::vector<uint8_t>& mask, const VoxelGrid& grid,
                                  double radius);

/// The voxels within `steps` 6-neighbour steps of `mask` (its 6-neighbour dilation `steps`
/// times, 0 ≤ steps ≤ 254): the city-block distance, exact, by forward and backward sweeps
/// along each axis.
std::vector<uint8_t> within_steps(const std::vector<uint8_t>& mask, const VoxelGrid& grid,
                                  int steps);

/// The voxel offsets within `mm` of a voxel (by distance_to_mask's float of their distance), in
/// order of distance: to decide a distance test at single voxels from their neighbourhood.
class VoxelOffsets {
 public:
  VoxelOffsets(const VoxelGrid& grid, double mm);
  const VoxelGrid& grid() const { return grid_; }
  /// Whether some voxel at an offset whose distance passes `within` (tested in order of
  /// distance; the first that fails ends the search) is a site: site(index, i, j, k).
  template <class Site, class Within>
  bool first(size_t voxel, Site&& site, Within&& within) const {
    const int nx = grid_.dims[0], ny = grid_.dims[1], nz = grid_.dims[2];
    const int i = static_cast<int>(voxel % nx), j = static_cast<int>((voxel / nx) % ny),
              k = static_cast<int>(voxel / (static_cast<size_t>(nx) * ny));
    for (size_t n = 0; n < offsets_.size(); ++n) {
      if (!within(distance_[n])) return false;
      const int a = i + offsets_[n][0], b = j + offsets_[n][1], c = k + offsets_[n][2];
      if (a < 0 || b < 0 || c < 0 || a >= nx || b >= ny || c >= nz) continue;
      if (site(grid_.index(a, b, c), a, b, c)) return true;
    }
    return false;
  }

 private:
  VoxelGrid grid_;
  std::vector<std::array<int, 3>> offsets_;
  std::vector<float> distance_;
};

/// distance_to_mask(mask)[voxel] > mm — the same test on the same float — from the voxels
/// around that one alone: for a few voxels, where a whole transform would cost more.
class LocalDistance {
 public:
  LocalDistance(const std::vector<uint8_t>& mask, const VoxelGrid& grid, float mm);
  bool farther(size_t voxel) const;

 private:
  const std::vector<uint8_t>& mask_;
  VoxelOffsets offsets_;
  float mm_;
};

/// open_by_ball(mask, grid, radius)[voxel] — the same tests on the same floats — from the voxels
/// around that one alone, the ball centres found on the way kept for the next voxels.
class LocalOpening {
 public:
  LocalOpening(const std::vector<uint8_t>& mask, const VoxelGrid& grid, double radius);
  bool contains(size_t voxel);

 private:
  bool is_centre(size_t voxel);
  const std::vector<uint8_t>& mask_;
  double reach_;  ///< radius + ½ voxel: the centres' depth, and how far a ball reaches from one
  VoxelOffsets offsets_;
  std::vector<int8_t> centre_;  ///< -1 not known yet
};

}  // namespace cranioplan
