#pragma once
// The wizard's steps by number.

namespace cranioplan {

/// The wizard's steps, by the numbers the session file (`go_to_step`, `complete_step`), the
/// user and `PlanState::current_step` use.
enum StepNumber : int {
  kLoadStep = 1,
  kPlaneStep,
  kMirrorStep,
  kClipStep,
  kEdgeMarkersStep,
  kSurfaceMarkersStep,
  kBuildStep,
  kSmoothStep,
  kExportStep,
};
inline constexpr int kStepCount = kExportStep;

}  // namespace cranioplan
