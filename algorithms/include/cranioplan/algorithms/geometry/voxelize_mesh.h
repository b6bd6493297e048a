#pragma once
// Solid voxelisation of closed meshes on axis-aligned grids: the common ground of accuracy
// metrics, overlap (penetration) checks and defect injection.
#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "cranioplan/model/mesh.h"
#include "cranioplan/model/volume.h"

namespace cranioplan {

/// An axis-aligned grid: voxel (i,j,k) has its centre at origin + spacing·(i,j,k).
struct VoxelGrid {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  ///< centre of voxel (0,0,0), mm
  double spacing = 0.5;                              ///< mm (>0)
  std::array<int, 3> dims{0, 0, 0};

  size_t size() const { return static_cast<size_t>(dims[0]) * dims[1] * dims[2]; }
  size_t index(int i, int j, int k) const {
    return (static_cast<size_t>(k) * dims[1] + j) * dims[0] + i;
  }
  Eigen::Vector3d center(int i, int j, int k) const {
    return origin + spacing * Eigen::Vector3d(i, j, k);
  }
  double voxel_volume() const { return spacing * spacing * spacing; }

  /// The grid that covers [lo, hi] with `pad` extra voxels on every side.
  static VoxelGrid covering(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double spacing,
                            int pad = 2);
  /// The same, coarser than `spacing` where needed so that it has at most `max_voxels`
  /// voxels (memory and time grow with the count).
  static VoxelGrid covering_at_most(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                                    double spacing, double max_voxels, int pad = 2);
};

/// Calls fn(i, j, k) for the voxels of `g` within `reach` mm of `center` along each axis (a
/// voxel more on the upper side), clipped to the grid: the box a tool of that reach can touch.
template <class Fn>
void for_voxels_near(const VoxelGrid& g, const Eigen::Vector3d& center, double reach, Fn&& fn) {
  const Eigen::Vector3d a = (center - Eigen::Vector3d::Constant(reach) - g.origin) / g.spacing,
                        b = (center + Eigen::Vector3d::Constant(reach) - g.origin) / g.spacing;
  for (int k = std::max(0, static_cast<int>(a.z()));
       k <= std::min(g.dims[2] - 1, static_cast<int>(b.z()) + 1); ++k)
    for (int j = std::max(0, static_cast<int>(a.y()));
         j <= std::min(g.dims[1] - 1, static_cast<int>(b.y()) + 1); ++j)
      for (int i = std::max(0, static_cast<int>(a.x()));
           i <= std::min(g.dims[0] - 1, static_cast<int>(b.x()) + 1); ++i)
        fn(i, j, k);
}

/// Bounding box of a mesh's vertices.
std::pair<Eigen::Vector3d, Eigen::Vector3d> mesh_bounds(const SkullMesh& mesh);

struct VoxelizeParams {
  /// A line along z through a hole in the surface (the cut where a CT scan ends and an exporter
  /// left the surface open, a small hole) crosses it an odd number of times, and parity along it
  /// is wrong on one side of the hole. true: such a line's voxels are decided by the lines along
  /// x and y through them that cross the surface an even number of times (parity-count voting,
  /// Nooruddin & Turk 2003), by parity along z when neither does. false: parity along z from
  /// below, pairing crossings up from the lowest, as plans saved before version 0.2 fitted
  /// implants to the bone. A closed surface gives the same mask either way.
  bool vote_through_holes = true;
};

/// 1 for voxels whose centre lies inside the mesh, else 0: the parity of the surface crossings
/// along z through the voxel centre, with votes along x and y where the line along z passes
/// through a hole (VoxelizeParams).
std::vector<uint8_t> voxelize_mesh(const SkullMesh& mesh, const VoxelGrid& grid,
                                   const VoxelizeParams& params = {});
class SurfaceLocator;
/// The same, reading only the faces that `locator` (the mesh's own, not moved) finds over the
/// grid's lines: the same mask, from a fraction of the faces when the grid covers a small part
/// of a large mesh (the fit to the bone voxelizes the skull on the implant's grid).
std::vector<uint8_t> voxelize_mesh(const SkullMesh& mesh, const VoxelGrid& grid,
                                   const VoxelizeParams& params, const SurfaceLocator& locator);

/// The mask as a Volume (values 0/1), for surface extraction.
Volume mask_volume(const std::vector<uint8_t>& mask, const VoxelGrid& grid);

}  // namespace cranioplan
