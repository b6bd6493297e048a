#pragma once
// Whether a CT belongs to a skull mesh: the CT's bone surface must lie on the mesh.
#include <string>

#include "cranioplan/algorithms/io/extract_bone_surface.h"
#include "cranioplan/model/mesh.h"
#include "cranioplan/model/volume.h"

namespace cranioplan {

struct CtAgreementParams {
  ExtractBoneSurfaceParams surface;  ///< the CT's bone surface (its threshold: the plan's)
  double max_median_mm = 1.0;        ///< the mesh's median distance to it, at most
  double max_p90_mm = 2.5;           ///< and its 90th percentile, at most
  size_t samples = 4000;             ///< mesh vertices looked at (spread over the mesh)
};

struct CtAgreement {
  bool agrees = false;
  double median_mm = 0.0;  ///< from the mesh's vertices to the CT's bone surface
  double p90_mm = 0.0;
  std::string message;  ///< what was measured, and why the CT is refused when it is
};

/// Measures how far the mesh lies from the CT's bone surface (extracted with `params.surface`):
/// a CT of this skull in its frame has both figures within a voxel or two; another patient, or
/// the same one in another frame (RAS for LPS, another origin), lies centimetres off.
CtAgreement ct_agreement(const SkullMesh& mesh, const Volume& ct,
                         const CtAgreementParams& params = {});

}  // namespace cranioplan
