#pragma once
// Known answers on real skulls: cut a defect out of a healthy skull, keeping what was removed
// as the ground-truth implant (as the AutoImplant / SkullBreak data sets were made).
#include <string>

#include "cranioplan/model/mesh.h"

namespace cranioplan {

struct InjectDefectParams {
  enum class Shape { Sphere, Cube };
  Shape shape = Shape::Sphere;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  ///< mm
  double size_mm = 40.0;                             ///< sphere diameter or cube edge, mm (>0)
  double voxel_mm = 0.4;                             ///< resolution of the cut, mm (0.1..2)
};

struct InjectDefectResult {
  enum class Status { Injected, NoBoneInDefect };
  Status status = Status::NoBoneInDefect;
  std::string message;
  SkullMesh defective;  ///< the skull without the defect: closed, outward-oriented
  SkullMesh implant;    ///< the removed bone: closed, outward-oriented
  double removed_volume_mm3 = 0.0;
  double seconds = 0.0;
  bool usable() const { return status == Status::Injected; }
};

/// Voxelises the (closed) skull, splits the voxels into those inside and outside the shape and
/// turns both back into surfaces; defective ∪ implant is the skull and they do not overlap (at
/// the voxel level).
InjectDefectResult inject_defect(const SkullMesh& skull, const InjectDefectParams& params);

}  // namespace cranioplan
