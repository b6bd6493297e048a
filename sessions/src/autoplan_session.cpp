#include "cranioplan/sessions/autoplan_session.h"

#include <filesystem>

#include "cranioplan/algorithms/propose_markers.h"

namespace cranioplan {

AutoplanSession autoplan_session(const std::string& skull_path, const Landmarks& landmarks,
                                 const AutoplanParams& params, const std::string& export_path,
                                 const SessionInfo& info, const ExtractBoneSurfaceParams& import) {
  AutoplanSession out;
  SessionInfo with_case = info;
  if (with_case.case_id.empty())
    with_case.case_id = std::filesystem::path(skull_path).stem().string();
  out.session = Session(with_case);
  Session& s = out.session;
  auto run = [&](Command c) {
    const PushResult r = s.push(std::move(c));
    if (!r.accepted) out.message = r.message;
    return r.accepted;
  };
  auto stop = [&](const std::string& why) {
    out.message = why;
    return std::move(out);
  };
  if (!run(commands::load_skull(skull_path, import))) return out;
  if (landmarks.nasion) run(commands::set_landmark("nasion", *landmarks.nasion));
  if (landmarks.orbit_left) run(commands::set_landmark("orbit_left", *landmarks.orbit_left));
  if (landmarks.orbit_right) run(commands::set_landmark("orbit_right", *landmarks.orbit_right));
  for (const auto& p : landmarks.midline) run(commands::set_landmark("midline", p));
  run(commands::fit_plane(params.plane));
  if (!s.state().plane) return stop("midsagittal plane: " + s.state().message);
  run(commands::mirror());
  run(commands::register_mirror(params.registration));
  // The opening, found here as the markers' command would find it (the same skull, plane and
  // detection): the mirror is registered again around it, as autoplan() does, with the region
  // recorded as the command's parameter so that replay needs no detection.
  {
    const PlanState& st = s.state();
    out.defect = detect_defect_near_plane(st.skull->surface->mesh, st.skull->surface->locator,
                                          *st.plane, params.propose.detect);
  }
  if (params.local_registration_mm > 0.0 && out.defect.found() && s.state().registration &&
      s.state().registration->usable()) {
    RegisterParams local = params.registration;
    local.initial = s.state().registration->transform;
    local.roi = local_registration_region(out.defect, params.local_registration_mm);
    run(commands::register_mirror(local));
  }
  // An unusable registration leaves the mirror where mirroring put it, as autoplan() does.
  if (!step_complete(s.state(), 3)) run(commands::complete_step(3));
  run(commands::complete_step(4));
  // The markers are proposed for the opening found above, and the proposal goes into the
  // command as its result.
  Command propose = commands::propose_markers(params.propose);
  if (out.defect.found() && s.state().mirrored) {
    const PlanState& st = s.state();
    propose.params["result"] = proposal_result(
        propose_markers_for_defect(out.defect, st.skull->surface->locator, st.mirrored->locator,
                                   params.propose, st.next_marker_id));
  }
  run(std::move(propose));
  if (s.state().markers.empty()) {
    out.status = AutoplanSession::Status::NoDefect;
    return stop(s.state().message);
  }
  run(commands::build_implant(params.implant));
  if (!s.state().implant) return stop(s.state().message);
  run(commands::complete_step(8));
  if (!export_path.empty() && !run(commands::export_implant(export_path))) return out;
  out.status = AutoplanSession::Status::Planned;
  out.message = s.state().proposal_message;
  return out;
}

}  // namespace cranioplan
