#include "cranioplan/algorithms/autoplan.h"

#include <chrono>
#include <cstdio>

#include "cranioplan/algorithms/mirror_mesh.h"
#include "cranioplan/algorithms/propose_markers.h"
#include "cranioplan/algorithms/surface_locator.h"

namespace cranioplan {

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

// From the detection on: `r` holds the plane and the global registration.
void plan_opening(const SkullMesh& skull, const SurfaceLocator& bone, const AutoplanParams& params,
                  StageTimer& timer, AutoplanResult& r) {
  const RigidTransform reflection = reflection_across(r.plane.plane);
  r.defect = detect_defect_near_plane(skull, bone, r.plane.plane, params.propose.detect);
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

  if (params.local_registration_mm > 0.0 && r.registration.usable()) {
    RegisterParams local = params.registration;
    local.initial = r.registration.transform;
    local.roi = local_registration_region(r.defect, params.local_registration_mm);
    const RegisterResult lr = register_mirror(skull, r.plane.plane, local);
    if (lr.usable()) r.registration = lr;
    timer.stage("local register");
  }
  r.mirror_motion = mirror_motion();
  const SurfaceLocator mirror = bone.moved(r.mirror_motion);
  MarkerProposal proposal = propose_markers_for_defect(r.defect, bone, mirror, params.propose);
  r.mirror_coverage = proposal.mirror_coverage;
  r.method_used = proposal.method_used;
  r.surfaces_message = proposal.surfaces_message;
  r.markers = std::move(proposal.markers);
  timer.stage("markers");
  if (!proposal.proposed()) {
    r.message = "markers: " + proposal.message;
    return;
  }

  ImplantParams implant = params.implant;
  implant.radial_center = r.defect.center;  // the rays that found the opening
  r.implant = build_implant(r.markers, &skull, &bone, implant);
  timer.stage("implant");
  if (!r.implant.usable()) {
    r.message = "implant: " + r.implant.message;
    return;
  }
  r.quality = check_implant(r.implant.mesh, &skull, &bone, QualityParams{});
  timer.stage("quality");
  r.status = AutoplanResult::Status::Planned;
  char buf[80];  // the fixed part; the messages around it can be long (they name rim stretches)
  std::snprintf(buf, sizeof(buf), "%s (mirror covers %.0f%% of the opening); ",
                r.method_used == PlanMethod::Mirror ? "mirror-guided" : "rim-only fitting",
                100.0 * r.mirror_coverage);
  r.message = r.defect.message + "; " + buf + r.surfaces_message;
}

// The plane and the global registration; false (and `r` says why) when the plane fails.
bool plane_and_registration(const SkullMesh& skull, const Landmarks& landmarks,
                            const AutoplanParams& params, StageTimer& timer, AutoplanResult& r) {
  r.plane = fit_sagittal_plane(skull, landmarks, params.plane);
  timer.stage("plane");
  if (!r.plane.usable()) {
    r.message = "midsagittal plane: " + r.plane.message;
    return false;
  }
  // The mirror is never built as a mesh here (register_mirror), and its locator is the skull's
  // locator moved (on a skull of two million triangles a mesh and a locator are a few hundred
  // megabytes each).
  r.registration = register_mirror(skull, r.plane.plane, params.registration);
  timer.stage("register");
  return true;
}

}  // namespace

AutoplanResult autoplan(const SkullMesh& skull, const Landmarks& landmarks,
                        const AutoplanParams& params) {
  AutoplanResult r;
  StageTimer timer(r.stage_seconds);
  if (!plane_and_registration(skull, landmarks, params, timer, r)) return r;
  const SurfaceLocator bone(skull);
  plan_opening(skull, bone, params, timer, r);
  return r;
}

std::vector<AutoplanResult> autoplan_all_openings(const SkullMesh& skull,
                                                  const Landmarks& landmarks,
                                                  const AutoplanParams& params) {
  AutoplanResult first;
  StageTimer timer(first.stage_seconds);
  if (!plane_and_registration(skull, landmarks, params, timer, first)) return {first};
  AutoplanResult shared;  // the plane and the global registration, before the local one
  shared.plane = first.plane;
  shared.registration = first.registration;
  const SurfaceLocator bone(skull);
  plan_opening(skull, bone, params, timer, first);
  std::vector<AutoplanResult> plans;
  plans.push_back(std::move(first));
  if (!plans.front().defect.found()) return plans;
  const Eigen::Vector3d centre = plans.front().defect.center;
  const std::vector<Eigen::Vector3d> axes = plans.front().defect.other_axes;
  for (const Eigen::Vector3d& axis : axes) {
    AutoplanParams each = params;
    each.propose.detect.near = centre + 100.0 * axis;
    AutoplanResult r = shared;
    StageTimer each_timer(r.stage_seconds);
    plan_opening(skull, bone, each, each_timer, r);
    plans.push_back(std::move(r));
  }
  for (AutoplanResult& r : plans) r.message = with_other_openings_planned(r.message);
  return plans;
}

}  // namespace cranioplan
