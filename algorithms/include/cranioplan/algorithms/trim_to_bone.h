#pragma once
// Fits an implant to the skull it is made for: the bone is subtracted from the implant on a fine
// voxel grid, slivers left on top of intact bone are removed, and the rest is meshed again with
// a smooth surface. An implant built a little larger than the opening thereby meets the cut face
// of the defect everywhere (no gap) and never enters the bone (no overlap).
#include <string>

#include "cranioplan/model/mesh.h"

namespace cranioplan {

struct TrimToBoneParams {
  double voxel_mm = 0.25;       ///< grid of the subtraction, mm (0.1..1)
  double min_feature_mm = 1.0;  ///< parts thinner than this (slivers on the bone) go, mm (≥ 0)
  double smoothing_mm = 0.3;    ///< Gaussian blur of the mask before meshing (σ), mm (≥ 0)
  double clearance_mm = 0.03;   ///< vertices put back onto the bone stay this far out of it, mm
};

struct TrimToBoneResult {
  enum class Status { Trimmed, Empty };
  Status status = Status::Empty;
  std::string message;
  SkullMesh mesh;            ///< closed, outward-oriented (the input, untouched, when Empty)
  double removed_mm3 = 0.0;  ///< volume taken away (bone overlap and slivers)
  double volume_mm3 = 0.0;   ///< volume kept
  double seconds = 0.0;
  bool usable() const { return status == Status::Trimmed; }
};

class SurfaceLocator;

/// `implant` and `skull` must be closed surfaces (the skull's bone as a solid). Vertices of the
/// result that the voxel grid left inside the bone (up to half a voxel) are put back onto the
/// bone's surface, using `skull_locator` when given (else one is built).
TrimToBoneResult trim_to_bone(const SkullMesh& implant, const SkullMesh& skull,
                              const TrimToBoneParams& params = {},
                              const SurfaceLocator* skull_locator = nullptr);

}  // namespace cranioplan
