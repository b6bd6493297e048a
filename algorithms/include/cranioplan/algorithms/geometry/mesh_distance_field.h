#pragma once
// A closed mesh as a signed distance field on a voxel grid: what implant operations that re-mesh
// the implant (drilling holes, adding fixation tabs) combine with other solids before meshing.
#include <cstdint>
#include <vector>

namespace cranioplan {

class SurfaceLocator;
struct VoxelGrid;

/// The signed distance to the surface located by `locator` (mm, positive inside) at the grid's
/// voxel centres, with `solid` the surface's voxel mask on that grid: exact (the closest point
/// on the surface) within two to three voxels of where the mask changes, ±`far_mm` elsewhere.
std::vector<float> signed_distance_near_surface(const SurfaceLocator& locator,
                                                const std::vector<uint8_t>& solid,
                                                const VoxelGrid& grid, float far_mm = 10.0f);

/// The smooth minimum of two signed distances (positive inside): their intersection, its edge
/// rounded over `k` mm (a cut's rim deburred, a tab's edges rounded).
double smooth_min(double a, double b, double k);

}  // namespace cranioplan
