#include "cranioplan/algorithms/planning/autoplan.h"

#include <chrono>
#include <cstdio>
#include <future>

#include "cranioplan/algorithms/alignment/mirror_mesh.h"
#include "cranioplan/algorithms/geometry/point_index.h"
#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/planning/detect_defect.h"
#include "cranioplan/algorithms/planning/propose_markers.h"
#include "cranioplan/model/parallel.h"

namespace cranioplan {

const char* status_name(AutoplanResult::Status status) {
  switch (status) {
    case AutoplanResult::Status::Planned:
      return "planned";
    case AutoplanResult::Status::NoDefect:
      return "no_defect";
    case AutoplanResult::Status::Failed:
      break;
  }
  return "failed";
}

namespace {

class StageTimer {
 public:
  explicit StageTimer(std::vector<std::pair<std::string, double>>& out) : out_(out) {}
  void stage(const std::string& name) {
    const auto now = std::chrono::steady_clock::now();
    out_.emplace_back(name, std::chrono::duration<double>(now - last_).count());
    last_ = now;
  }

 private:
  std::vector<std::pair<std::string, double>>& out_;
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

// From the detection on: `r` holds the plane and the global registration. `all_openings`: the
// other openings are planned as well, and the messages say so.
void plan_opening(const SkullMesh& skull, const SurfaceLocator& bone, const VertexCloud& cloud,
                  const AutoplanParams& params, const ShapeModel* shape_model, bool all_openings,
                  StageTimer& timer, AutoplanResult& r) {
  const RigidTransform reflection = reflection_across(r.plane.plane);
  r.defect = autoplan_stages::detect(skull, bone, r.plane.plane, params);
  if (all_openings) r.defect.message = r.defect.describe(true);
  timer.stage("detect");
  auto mirror_motion = [&] {
    return r.registration.usable() ? r.registration.transform * reflection : reflection;
  };
  if (!r.defect.found()) {
    r.mirror_motion = mirror_motion();
    r.status = AutoplanResult::Status::NoDefect;
    r.message = r.defect.message;
    return;
  }
  const std::optional<autoplan_stages::LocalRegistration> local =
      autoplan_stages::local_registration(skull, r.plane.plane, r.defect, r.registration, params,
                                          &cloud);
  if (local) {
    r.registration = autoplan_stages::registration_used(r.registration, local);
    timer.stage("local register");
  }
  r.mirror_motion = mirror_motion();
  const SurfaceLocator mirror = bone.moved(r.mirror_motion);
  MarkerProposal proposal =
      autoplan_stages::markers(r.defect, skull, bone, mirror, params, 1, shape_model, &r.shape_fit);
  r.mirror_coverage = proposal.mirror_coverage;
  r.sources = proposal.sources;
  r.method_used = proposal.method_used;
  r.surfaces_message = proposal.surfaces_message;
  r.markers = std::move(proposal.markers);
  timer.stage("markers");
  if (!proposal.proposed()) {
    r.message = "markers: " + proposal.message;
    return;
  }

  r.implant = build_implant(r.markers, &skull, &bone,
                            autoplan_stages::implant_params(r.defect, r.plane.plane, params));
  timer.stage("implant");
  if (!r.implant.usable()) {
    r.message = "implant: " + r.implant.message;
    return;
  }
  r.quality = check_implant(
      r.implant.mesh, &skull, &bone,
      quality_params_for(autoplan_stages::implant_params(r.defect, r.plane.plane, params),
                         r.implant));
  timer.stage("quality");
  r.status = AutoplanResult::Status::Planned;
  r.message = r.defect.message + "; " + describe_method(r.method_used, r.mirror_coverage) + "; " +
              r.surfaces_message;
}

// The skull's search tree, built on a thread of its own while the plane and the registration
// are found: they do not use it (the detection is the first stage that does), and for most of
// their time they keep one core of two busy. The tree does not depend on the threads.
std::future<SurfaceLocator> locator_meanwhile(const SkullMesh& skull) {
  return std::async(beside(), [&skull] { return SurfaceLocator(skull); });
}

// The plane and the global registration; false (and `r` says why) when the plane fails.
bool plane_and_registration(const SkullMesh& skull, const Landmarks& landmarks,
                            const VertexCloud& cloud, const AutoplanParams& params,
                            StageTimer& timer, AutoplanResult& r) {
  r.plane = autoplan_stages::plane(skull, landmarks, params, &cloud);
  timer.stage("plane");
  if (!r.plane.usable()) {
    r.message = "midsagittal plane: " + r.plane.message;
    return false;
  }
  r.registration = autoplan_stages::registration(skull, r.plane.plane, params, &cloud);
  timer.stage("register");
  return true;
}

}  // namespace

namespace autoplan_stages {

PlaneFit plane(const SkullMesh& skull, const Landmarks& landmarks, const AutoplanParams& params,
               const VertexCloud* cloud) {
  return fit_sagittal_plane(skull, landmarks, params.plane, cloud);
}

RegisterResult registration(const SkullMesh& skull, const Plane& plane,
                            const AutoplanParams& params, const VertexCloud* cloud) {
  return register_mirror(skull, plane, params.registration, cloud);
}

DefectRegion detect(const SkullMesh& skull, const SurfaceLocator& bone, const Plane& plane,
                    const AutoplanParams& params) {
  return detect_defect_near_plane(skull, bone, plane, params.propose.detect);
}

std::optional<LocalRegistration> local_registration(const SkullMesh& skull, const Plane& plane,
                                                    const DefectRegion& defect,
                                                    const RegisterResult& global,
                                                    const AutoplanParams& params,
                                                    const VertexCloud* cloud) {
  if (params.local_registration_mm <= 0.0 || !defect.found() || !global.usable())
    return std::nullopt;
  LocalRegistration local;
  local.params = params.registration;
  local.params.initial = global.transform;
  local.params.roi = local_registration_region(defect, params.local_registration_mm);
  local.result = register_mirror(skull, plane, local.params, cloud);
  return local;
}

const RegisterResult& registration_used(const RegisterResult& global,
                                        const std::optional<LocalRegistration>& local) {
  return local && local->result.usable() ? local->result : global;
}

MarkerProposal markers(const DefectRegion& defect, const SkullMesh& skull,
                       const SurfaceLocator& bone, const SurfaceLocator& mirror,
                       const AutoplanParams& params, int first_id, const ShapeModel* model,
                       std::optional<ShapeFit>* fit) {
  return propose_markers_with_model(defect, skull, bone, mirror, params.propose, first_id, model,
                                    params.shape_prior, fit);
}

ImplantParams implant_params(const DefectRegion& defect, const Plane& plane,
                             const AutoplanParams& params) {
  ImplantParams implant = params.implant;
  implant.radial_center = defect.center;  // the rays that found the opening
  implant.scan_ends = defect.scan_ends;   // where the opening runs into the scan's end
  if (implant.tabs.any() && !implant.tabs.midline) implant.tabs.midline = plane;
  return implant;
}

}  // namespace autoplan_stages

Eigen::Vector3d point_towards_other_opening(const DefectRegion& first, size_t k) {
  return first.center + 100.0 * first.other_axes.at(k);
}

AutoplanResult autoplan(const SkullMesh& skull, const Landmarks& landmarks,
                        const AutoplanParams& params, const ShapeModel* shape_model) {
  AutoplanResult r;
  StageTimer timer(r.stage_seconds);
  std::future<SurfaceLocator> bone = locator_meanwhile(skull);
  const VertexCloud cloud(skull);
  if (!plane_and_registration(skull, landmarks, cloud, params, timer, r)) return r;
  plan_opening(skull, bone.get(), cloud, params, shape_model, false, timer, r);
  return r;
}

std::vector<AutoplanResult> autoplan_all_openings(const SkullMesh& skull,
                                                  const Landmarks& landmarks,
                                                  const AutoplanParams& params,
                                                  const ShapeModel* shape_model) {
  AutoplanResult first;
  StageTimer timer(first.stage_seconds);
  std::future<SurfaceLocator> building = locator_meanwhile(skull);
  const VertexCloud cloud(skull);
  if (!plane_and_registration(skull, landmarks, cloud, params, timer, first)) return {first};
  AutoplanResult shared;  // the plane and the global registration, before the local one
  shared.plane = first.plane;
  shared.registration = first.registration;
  const SurfaceLocator bone = building.get();
  plan_opening(skull, bone, cloud, params, shape_model, true, timer, first);
  std::vector<AutoplanResult> plans;
  plans.push_back(std::move(first));
  if (!plans.front().defect.found()) return plans;
  const DefectRegion first_opening = plans.front().defect;
  for (size_t k = 0; k < first_opening.other_axes.size(); ++k) {
    AutoplanParams each = params;
    each.propose.detect.near = point_towards_other_opening(first_opening, k);
    AutoplanResult r = shared;
    StageTimer each_timer(r.stage_seconds);
    plan_opening(skull, bone, cloud, each, shape_model, true, each_timer, r);
    plans.push_back(std::move(r));
  }
  return plans;
}

}  // namespace cranioplan
