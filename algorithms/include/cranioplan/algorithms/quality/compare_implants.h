#pragma once
// Accuracy of an implant against a reference, as in the paper's inter-user analysis and the
// AutoImplant challenges: Dice, boundary Dice, Hausdorff distances, mean surface distance.
#include <string>

#include "cranioplan/model/mesh.h"

namespace cranioplan {

struct CompareParams {
  double spacing_mm = 0.5;    ///< common voxel grid, mm (0.1..2)
  double boundary_mm = 10.0;  ///< boundary Dice: voxels within this of the defective skull
};

struct CompareResult {
  double dice = 0.0;             ///< 2|A∩B| / (|A| + |B|)
  double boundary_dice = -1.0;   ///< same, restricted near the defective skull; −1 without one
  double hausdorff_mm = 0.0;     ///< largest surface-voxel distance, both directions
  double hd95_mm = 0.0;          ///< 95th percentile of both directions' distances together
  double mean_surface_mm = 0.0;  ///< mean of both directions' distances together
  double volume_a_mm3 = 0.0, volume_b_mm3 = 0.0;
  long long voxels_a = 0, voxels_b = 0, voxels_both = 0;
  double seconds = 0.0;
};

/// Voxelises both (closed) meshes on a common axis-aligned grid and measures their agreement.
/// Surface voxels are voxels of a mask with a 6-neighbour outside it; distances are between
/// their centres. When one mask is empty the distances are infinite.
CompareResult compare_implants(const SkullMesh& a, const SkullMesh& b,
                               const SkullMesh* defective_skull = nullptr,
                               const CompareParams& params = {});

}  // namespace cranioplan
