#pragma once
// The implant against the soft tissue under it, on the patient's CT: after a decompression the
// brain and dura may bulge into the defect, and an implant shaped on the skull's curvature
// alone would press on them. The check measures how much of the implant (the half of it under
// its inner surface) lies where the CT shows soft tissue, and how close its inner surface comes
// to soft tissue beneath it.
#include <Eigen/Core>
#include <limits>
#include <string>
#include <vector>

#include "cranioplan/model/mesh.h"
#include "cranioplan/model/volume.h"

namespace cranioplan {

struct SoftTissueParams {
  /// Hounsfield units read as brain, dura or muscle: above cerebrospinal fluid (0–15 HU) and
  /// fat, below bone. Air, fat and fluid under the implant are fine.
  double soft_min_hu = 20.0, soft_max_hu = 200.0;
  /// Bone from here up. Where bone meets fluid or air a CT's samples (and their interpolation)
  /// pass through the soft-tissue range: a point with bone among the 27 samples around it is
  /// not tissue.
  double bone_hu = 300.0;
  double probe_mm = 10.0;  ///< how far under the inner surface to look for tissue, mm (>0)
  size_t samples = 4000;   ///< inner-surface points looked from (spread over it)
};

struct SoftTissueCheck {
  bool checked = false;  ///< false: the volume is a mask, or the implant is empty
  /// Implant volume (its part nearer the inner surface than the outer) where the CT shows soft
  /// tissue, mm³.
  double intrusion_mm3 = 0.0;
  /// Least distance from the inner surface down to soft tissue, mm (0 when it lies in tissue;
  /// infinity when there is none within probe_mm).
  double closest_mm = std::numeric_limits<double>::infinity();
  std::vector<Eigen::Vector3d> intrusion;  ///< the intruding voxels' centres, for display
  std::string message;
};

/// `inside` is a point of the cranial cavity (the skull's centre), which tells the implant's
/// inner surface (facing it) from its outer.
SoftTissueCheck check_soft_tissue(const SkullMesh& implant, const Volume& ct,
                                  const Eigen::Vector3d& inside,
                                  const SoftTissueParams& params = {});

}  // namespace cranioplan
