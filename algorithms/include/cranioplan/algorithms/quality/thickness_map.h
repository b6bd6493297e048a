#pragma once
// The implant's thickness at every vertex, and the skull's gap to the implant around it: what
// the wizard's thickness map colours (the implant by how thick it is, the skull near the rim by
// how far the implant stands off it).
#include <Eigen/Core>
#include <vector>

#include "cranioplan/model/mesh.h"

namespace cranioplan {

class SurfaceLocator;
struct VoxelGrid;

struct ThicknessMapParams {
  double voxel_mm = 0.25;       ///< grid of the implant's solid (bounds the thickness), mm
  double max_voxels = 8e6;      ///< a large implant's grid is coarsened to this many voxels
  double skull_reach_mm = 4.0;  ///< skull vertices farther from the implant get no gap, mm
};

struct ThicknessMap {
  /// Per implant vertex (by index): the thickness through the implant there, mm.
  std::vector<float> implant_mm;
  /// Per skull vertex (by index): the distance to the implant's surface, mm; NaN farther than
  /// the reach (or without a skull).
  std::vector<float> skull_gap_mm;
  double min_mm = 0.0, median_mm = 0.0, max_mm = 0.0;  ///< of the implant's vertices
};

/// The thickness at each implant vertex is measured as the quality report measures it at a
/// face: along the inward normal (area-weighted over the vertex's faces) to the opposite
/// surface, but at most the diameter of the deepest ball that ray passes in the implant's solid.
ThicknessMap thickness_map(const SkullMesh& implant, const SkullMesh* skull,
                           const ThicknessMapParams& params = {});

/// The thickness through `implant` (located by `self`) from its surface point `at` along the
/// inward direction `-outward` (unit): the distance to the opposite surface, at most twice the
/// deepest voxel of `depth` (depth_in_mask of the implant's solid on `grid`) the ray passes plus
/// a voxel — on a curved plate a normal can leave at a grazing angle and run along it. 0 when
/// the ray meets no surface.
double thickness_through(const SurfaceLocator& self, const Eigen::Vector3d& at,
                         const Eigen::Vector3d& outward, const std::vector<float>& depth,
                         const VoxelGrid& grid);

}  // namespace cranioplan
