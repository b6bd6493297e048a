#pragma once
// The implant as a labelmap on a CT's grid, written as NRRD (and as a 3D Slicer segmentation,
// .seg.nrrd), so that it opens over the CT in 3D Slicer and other viewers.
#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "cranioplan/model/mesh.h"
#include "cranioplan/model/volume.h"

namespace cranioplan {

/// 1 for each sample of `grid` (its dims, directions and origin, LPS; the samples themselves
/// are not used) whose position lies inside the closed `mesh`, else 0; i fastest. Oblique and
/// sheared grids are exact: the mesh is carried into the grid's index space and voxelized there.
std::vector<uint8_t> labelmap_on_grid(const SkullMesh& mesh, const Volume& grid);

/// A segment of a Slicer segmentation.
struct LabelSegment {
  std::string name = "implant";
  Eigen::Vector3d color{0.93, 0.72, 0.25};  ///< RGB 0..1
};

/// Writes `labels` (values 0 and 1, on `grid`) as a gzip-compressed uint8 NRRD in LPS with the
/// grid's space directions and origin. A path ending in .seg.nrrd also carries Slicer's
/// segmentation fields: one segment, label value 1, named and coloured by `segment`, with its
/// extent. Written atomically; throws InputError when the file cannot be written or `labels`
/// does not match the grid.
void write_labelmap_nrrd(const std::vector<uint8_t>& labels, const Volume& grid,
                         const std::string& path, const LabelSegment& segment = {});

}  // namespace cranioplan
