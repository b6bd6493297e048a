#pragma once
// The implant against the soft tissue under it, on the patient's CT: after a decompression the
// brain and dura may bulge into the defect, and an implant shaped on the skull's curvature
// alone would press on them. The check measures how much of the implant (the half of it under
// its inner surface) lies where the CT shows soft tissue, and how close its inner surface comes
// to soft tissue beneath it. CT numbers do not tell the scalp from the dura and brain, depth
// does: tissue within the scalp's thickness under the skin is scalp (the thickness measured on
// the CT over the intact bone around the defect). Scalp in the implant's place has sunk into an
// old defect and is lifted by the implant: measured apart, not a finding. Only tissue deeper
// than that — brain or dura reaching into the defect — counts as intrusion.
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
  /// Air (the skin's outside) below this, HU.
  double air_hu = -400.0;
  /// The scalp's thickness is measured this far beyond the implant's side wall, mm.
  double ring_mm = 5.0;
  /// The scalp's thickness when the CT shows none around the defect, mm.
  double default_scalp_mm = 6.0;
  /// Brain or dura reaching further than this above the implant's inner surface is a finding
  /// (the implant would press on it); less is the dura and the CT's partial volume, mm.
  double warn_reach_mm = 2.0;
};

struct SoftTissueCheck {
  bool checked = false;  ///< false: the volume is a mask, or the implant is empty
  /// Implant volume (its part nearer the inner surface than the outer) where the CT shows soft
  /// tissue under a skin that stands over the implant (brain or dura bulging into the defect),
  /// mm³: the finding.
  double intrusion_mm3 = 0.0;
  /// Implant volume (same part) where the tissue is a scalp sunk into the defect (within the
  /// scalp's thickness under the skin), mm³: the implant will lift it; not a finding.
  double sunken_scalp_mm3 = 0.0;
  /// The scalp's thickness over the bone around the defect (median), mm.
  double scalp_mm = 0.0;
  /// How far above the implant's inner surface the brain or dura reaches (95th percentile of
  /// the intruding voxels' depth into the implant), mm; 0 without intrusion.
  double intrusion_reach_mm = 0.0;
  /// Whether it reaches beyond `warn_reach_mm`: the implant would press on the brain.
  bool finding = false;
  /// Least distance from the inner surface down to soft tissue, mm (0 when it lies in tissue
  /// other than a sunken scalp; infinity when there is none within probe_mm).
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
