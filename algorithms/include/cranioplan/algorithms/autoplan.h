#pragma once
// Automatic planning: the starting point a surgeon then edits. plane → mirror → register →
// detect the defect → propose markers → smooth → implant → quality report, with every stage's
// output kept for the caller.
#include <string>
#include <utility>
#include <vector>

#include "cranioplan/algorithms/build_implant.h"
#include "cranioplan/algorithms/check_implant.h"
#include "cranioplan/algorithms/detect_defect.h"
#include "cranioplan/algorithms/fit_sagittal_plane.h"
#include "cranioplan/algorithms/register_icp.h"
#include "cranioplan/algorithms/smooth_markers.h"
#include "cranioplan/model/landmarks.h"
#include "cranioplan/model/marker.h"

namespace cranioplan {

enum class PlanMethod { Auto, Mirror, RimOnly };
const char* to_string(PlanMethod m);

struct AutoplanParams {
  PlaneFitParams plane;
  RegisterParams registration;
  DetectDefectParams detect;
  PlanMethod method = PlanMethod::Auto;  ///< Auto: mirror where it covers the defect, else rim
  double min_mirror_coverage = 0.8;      ///< Auto uses the mirror above this coverage, 0..1
  double edge_spacing_mm = 4.0;          ///< proposed edge markers along the rim, mm
  double surface_spacing_mm = 6.0;       ///< proposed surface and support markers, mm
  SmoothParams smooth{10.0, 2.0, 1};     ///< applied to mirror surface markers (projected back)
  ImplantParams implant = [] {
    ImplantParams p;
    p.surface_smoothing = 0.003;
    return p;
  }();
};

struct AutoplanResult {
  enum class Status { Planned, NoDefect, Failed };
  Status status = Status::Failed;
  std::string message;
  PlaneFit plane;
  RegisterResult registration;
  SkullMesh mirrored;  ///< mirrored and registered onto the skull
  DefectRegion defect;
  PlanMethod method_used = PlanMethod::RimOnly;
  double mirror_coverage = 0.0;  ///< fraction of the opening's rays that meet mirrored bone
  std::vector<Marker> markers;   ///< proposed (after smoothing)
  ImplantResult implant;
  QualityReport quality;
  std::vector<std::pair<std::string, double>> stage_seconds;
  bool planned() const { return status == Status::Planned; }
};

AutoplanResult autoplan(const SkullMesh& skull, const Landmarks& landmarks,
                        const AutoplanParams& params = {});

}  // namespace cranioplan
