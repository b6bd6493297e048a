#pragma once
// Automatic planning: the starting point a surgeon then edits. plane → mirror → register →
// detect the defect → register again around it → propose markers → implant → quality report,
// with every stage's output kept for the caller. The stages are named functions
// (`autoplan_stages`); autoplan() chains them, and a session records each one's result as the
// command that would have found it (autoplan_session), so a plan is the same however it is made.
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cranioplan/algorithms/alignment/fit_sagittal_plane.h"
#include "cranioplan/algorithms/alignment/register_icp.h"
#include "cranioplan/algorithms/implant/build_implant.h"
#include "cranioplan/algorithms/planning/propose_markers.h"
#include "cranioplan/algorithms/planning/shape_prior.h"
#include "cranioplan/algorithms/quality/check_implant.h"
#include "cranioplan/model/landmarks.h"
#include "cranioplan/model/marker.h"

namespace cranioplan {

struct AutoplanParams {
  PlaneFitParams plane;
  RegisterParams registration;
  ProposeParams propose;  ///< defect detection and marker proposal
  /// After the defect is found, the mirror is registered again on the bone within this margin
  /// of the opening (mm; 0: off), so the healthy side fits the defect's surroundings rather than
  /// the whole skull.
  double local_registration_mm = 25.0;
  /// Fitting a shape model of the normal skull, when the plan is given one.
  ShapePriorParams shape_prior;
  /// The shell, fitted to the bone (built 4 mm over it and the skull subtracted), so that the
  /// automatic implant meets the cut face all around without entering the bone.
  ImplantParams implant = [] {
    ImplantParams p;
    p.surface_smoothing = 0.003;
    p.fit_to_bone_mm = 4.0;
    return p;
  }();
};

struct AutoplanResult {
  enum class Status { Planned, NoDefect, Failed };
  Status status = Status::Failed;
  std::string message;
  PlaneFit plane;
  RegisterResult registration;
  /// The skull's motion onto its mirror image, registered: the reflection across the plane, then
  /// the registration (an improper transform). The mirrored skull is
  /// `transform_mesh(mirror_mesh(skull, plane.plane), registration.transform)`, and its locator
  /// `SurfaceLocator(skull).moved(mirror_motion)`; autoplan builds neither mesh.
  RigidTransform mirror_motion;
  DefectRegion defect;
  PlanMethod method_used = PlanMethod::RimOnly;
  double mirror_coverage = 0.0;  ///< fraction of the opening's rays that meet mirrored bone
  /// The shape model's fit, when the plan was given a model (used or not: `usable()`; Skipped
  /// when the plan did not need it).
  std::optional<ShapeFit> shape_fit;
  SurfaceSources sources;        ///< which sources shaped the surfaces over the opening
  std::string surfaces_message;  ///< how the defect's surfaces were fitted to the intact ring
  std::vector<Marker> markers;   ///< proposed (after smoothing)
  ImplantResult implant;
  QualityReport quality;
  std::vector<std::pair<std::string, double>> stage_seconds;
  bool planned() const { return status == Status::Planned; }
};

/// The status's name in every command's output: "planned", "no_defect" or "failed".
const char* status_name(AutoplanResult::Status status);

/// `shape_model` (may be null): a model of the normal skull to guide the missing bone's surfaces
/// (fitted around the opening; when it fits poorly the plan goes on as without it and says so).
AutoplanResult autoplan(const SkullMesh& skull, const Landmarks& landmarks,
                        const AutoplanParams& params = {}, const ShapeModel* shape_model = nullptr);

struct VertexCloud;

/// The stages of the automatic plan, in the order autoplan() runs them. `cloud`, when given, is
/// the skull's VertexCloud, made once for the plane and the registrations (the same results).
namespace autoplan_stages {

/// The midsagittal plane (from the landmarks when they give one).
PlaneFit plane(const SkullMesh& skull, const Landmarks& landmarks, const AutoplanParams& params,
               const VertexCloud* cloud = nullptr);
/// The skull's mirror image across `plane` registered onto the skull (no mirrored mesh is built:
/// on a skull of two million triangles a mesh and its locator are a few hundred megabytes each).
RegisterResult registration(const SkullMesh& skull, const Plane& plane,
                            const AutoplanParams& params, const VertexCloud* cloud = nullptr);
/// The opening to plan, seen from inside the cavity (detect_defect_near_plane;
/// `params.propose.detect`: `near` chooses among several, `center` starts the rays elsewhere).
DefectRegion detect(const SkullMesh& skull, const SurfaceLocator& bone, const Plane& plane,
                    const AutoplanParams& params);

struct LocalRegistration {
  RegisterParams params;  ///< the global registration's, started from it, within a region
  RegisterResult result;  ///< usable or not (an unusable one keeps the global registration)
};
/// The mirror registered again within `params.local_registration_mm` of the opening, started from
/// the global registration; none when that margin is 0, or without a defect or a usable global
/// registration to start from.
std::optional<LocalRegistration> local_registration(const SkullMesh& skull, const Plane& plane,
                                                    const DefectRegion& defect,
                                                    const RegisterResult& global,
                                                    const AutoplanParams& params,
                                                    const VertexCloud* cloud = nullptr);
/// The registration a plan goes on with: the local one when it is usable, else the global one.
const RegisterResult& registration_used(const RegisterResult& global,
                                        const std::optional<LocalRegistration>& local);
/// Markers for the opening, from `first_id` on; `mirror` locates the registered mirror, `model`
/// (may be null) a shape model to fit and guide the surfaces where the plan needs it, `fit`
/// (may be null) receives its fit (propose_markers_with_model).
MarkerProposal markers(const DefectRegion& defect, const SkullMesh& skull,
                       const SurfaceLocator& bone, const SurfaceLocator& mirror,
                       const AutoplanParams& params, int first_id = 1,
                       const ShapeModel* model = nullptr, std::optional<ShapeFit>* fit = nullptr);
/// The implant's parameters: the automatic plan's, in the frame of the rays that found the
/// opening, with the plan's plane as the tabs' midline (when tabs are asked without one).
ImplantParams implant_params(const DefectRegion& defect, const Plane& plane,
                             const AutoplanParams& params);

}  // namespace autoplan_stages

/// A point that chooses the `k`-th further opening of a plan whose opening is `first`: along
/// a ray through it from the first's centre (`DefectRegion::other_axes`), for
/// `DetectDefectParams::near`.
Eigen::Vector3d point_towards_other_opening(const DefectRegion& first, size_t k);

/// Every opening large enough to be a defect (bilateral defects), each planned to its own
/// implant. The first plan is autoplan's (the largest opening, or the one `near` chooses); each
/// further one is chosen by a ray through it (`DefectRegion::other_axes`). The plane and the
/// global registration are found once and shared (each plan still registers the mirror again
/// around its own opening); their times are in the first plan's `stage_seconds` only. Each
/// message says the other openings are planned as well. One plan (NoDefect or Failed) when the
/// first finds no defect or the plane fails.
std::vector<AutoplanResult> autoplan_all_openings(const SkullMesh& skull,
                                                  const Landmarks& landmarks,
                                                  const AutoplanParams& params = {},
                                                  const ShapeModel* shape_model = nullptr);

}  // namespace cranioplan
