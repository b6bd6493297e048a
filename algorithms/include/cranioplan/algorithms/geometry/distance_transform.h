#pragma once
// Exact Euclidean distance transform of a voxel mask (Felzenszwalb & Huttenlocher's lower
// envelope of parabolas, one axis at a time): the ground of thickness and clearance measures.
#include <cstdint>
#include <vector>

#include "cranioplan/algorithms/geometry/voxelize_mesh.h"

namespace cranioplan {

/// For every voxel, the distance (mm) from its centre to the centre of the nearest voxel whose
/// mask value is non-zero: 0 on the mask itself, +infinity everywhere when the mask is empty.
std::vector<float> distance_to_mask(const std::vector<uint8_t>& mask, const VoxelGrid& grid);

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

/// distance_to_mask(mask)[voxel] > mm — the same test on the same float — from the voxels
/// around that one alone: for a few voxels, where a whole transform would cost more.
bool farther_than(const std::vector<uint8_t>& mask, const VoxelGrid& grid, size_t voxel, float mm);

/// open_by_ball(mask, grid, radius)[voxel] — the same tests on the same floats — from the voxels
/// around that one alone. `centre` caches ball_centres over calls on the same mask: as many
/// entries as the grid has voxels, -1 where not known yet.
bool in_opening(const std::vector<uint8_t>& mask, const VoxelGrid& grid, size_t voxel,
                double radius, std::vector<int8_t>& centre);

}  // namespace cranioplan
