#include "cranioplan/algorithms/quality/inject_defect.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>

#include "cranioplan/algorithms/geometry/voxelize_mesh.h"
#include "cranioplan/algorithms/io/extract_bone_surface.h"

namespace cranioplan {

bool FlapCut::contains(const Eigen::Vector3d& x) const {
  const Eigen::Vector3d d = x - apex;
  const double z = d.dot(axis);
  const Eigen::Vector3d across = axis.cross(along);
  const double a = std::atan2(d.dot(along), z) / half_length_rad;
  const double b = std::atan2(d.dot(across), z) / half_width_rad;
  if (a * a + b * b > 1.0) return false;
  if (floor && floor->signed_distance(x) < 0.0) return false;
  if (!midline) return true;
  const double s = midline->signed_distance(x);
  if (one_side != 0 && s * one_side < 0.0) return false;
  return std::abs(s) >= midline_margin_mm;
}

bool in_defect(const InjectDefectParams& params, const Eigen::Vector3d& x) {
  const Eigen::Vector3d d = x - params.center;
  const double half = params.size_mm / 2.0;
  switch (params.shape) {
    case InjectDefectParams::Shape::Sphere:
      return d.squaredNorm() <= half * half;
    case InjectDefectParams::Shape::Cube:
      return d.cwiseAbs().maxCoeff() <= half;
    case InjectDefectParams::Shape::Flap:
      return params.flap.contains(x);
  }
  return false;
}

InjectDefectResult inject_defect(const SkullMesh& skull, const InjectDefectParams& params) {
  const auto t0 = std::chrono::steady_clock::now();
  InjectDefectResult result;
  const auto [lo, hi] = mesh_bounds(skull);
  const VoxelGrid grid = VoxelGrid::covering(lo, hi, std::clamp(params.voxel_mm, 0.1, 2.0));
  const std::vector<uint8_t> bone = voxelize_mesh(skull, grid);
  std::vector<uint8_t> kept(bone.size(), 0), removed(bone.size(), 0);
  size_t removed_count = 0;
  for (int k = 0; k < grid.dims[2]; ++k)
    for (int j = 0; j < grid.dims[1]; ++j)
      for (int i = 0; i < grid.dims[0]; ++i) {
        const size_t idx = grid.index(i, j, k);
        if (!bone[idx]) continue;
        const bool inside = in_defect(params, grid.center(i, j, k));
        (inside ? removed : kept)[idx] = 1;
        removed_count += inside;
      }
  if (removed_count == 0) {
    result.message = "the defect region contains no bone of the skull";
    return result;
  }
  ExtractBoneSurfaceParams all;
  all.largest_piece_only = false;
  all.min_piece_triangles = 1;
  result.defective = extract_bone_surface(mask_volume(kept, grid), all).mesh;
  result.implant = extract_bone_surface(mask_volume(removed, grid), all).mesh;
  result.removed_volume_mm3 = static_cast<double>(removed_count) * grid.voxel_volume();
  result.status = InjectDefectResult::Status::Injected;
  result.message = "removed " + std::to_string(static_cast<long long>(result.removed_volume_mm3)) +
                   " mm³ of bone";
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

}  // namespace cranioplan
