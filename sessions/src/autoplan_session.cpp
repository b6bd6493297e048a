#include "cranioplan/sessions/autoplan_session.h"

#include <chrono>
#include <filesystem>

#include "cranioplan/algorithms/io/file_io.h"
#include "cranioplan/algorithms/shape/shape_model.h"
#include "cranioplan/sessions/plan_files.h"
#include "cranioplan/sessions/sha256.h"

namespace cranioplan {

const char* status_name(AutoplanSession::Status status) {
  switch (status) {
    case AutoplanSession::Status::Planned:
      return status_name(AutoplanResult::Status::Planned);
    case AutoplanSession::Status::NoDefect:
      return status_name(AutoplanResult::Status::NoDefect);
    case AutoplanSession::Status::Failed:
      break;
  }
  return status_name(AutoplanResult::Status::Failed);
}

namespace {

// A search run outside its command, and the time it took, for the command to carry.
class Stopwatch {
 public:
  double ms() const {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_)
        .count();
  }

 private:
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

// `command` carrying what its search found, and how long the search took.
Command recorded(Command command, const Json& result, double ms) {
  command.params["result"] = result;
  command.meta.duration_ms = ms;
  return command;
}

}  // namespace

AutoplanSession autoplan_session(const std::string& skull_path, const Landmarks& landmarks,
                                 const AutoplanParams& params, const std::string& export_path,
                                 const SessionInfo& info, const ExtractBoneSurfaceParams& import,
                                 bool others_planned, const std::string& shape_model) {
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
  // The engine's stages (autoplan_stages), each recorded as the command that would have found
  // the same: a replay applies what they found instead of searching again.
  const std::shared_ptr<const SkullInput> skull = s.state().skull;
  const SkullMesh& mesh = skull->surface->mesh;
  const SurfaceLocator& bone = skull->surface->locator;
  {
    const Stopwatch t;
    const PlaneFit fit = autoplan_stages::plane(mesh, s.state().landmarks, params);
    run(recorded(commands::fit_plane(params.plane), to_json(fit), t.ms()));
  }
  if (!s.state().plane) return stop("midsagittal plane: " + s.state().message);
  const Plane plane = *s.state().plane;
  run(commands::mirror());
  RegisterResult global;
  {
    const Stopwatch t;
    global = autoplan_stages::registration(mesh, plane, params);
    run(recorded(commands::register_mirror(params.registration), to_json(global), t.ms()));
  }
  const Stopwatch detect_time;
  AutoplanParams detecting = params;  // the scan's borders from the report made at load
  take_scan_borders(detecting.propose.detect, skull->surface->loaded.report);
  out.defect = autoplan_stages::detect(mesh, bone, plane, detecting);
  const double detect_ms = detect_time.ms();
  if (others_planned) out.defect.message = out.defect.describe(true);
  {
    // Found by the proposal's search below, and recorded with it; the registration around the
    // opening (an unusable one keeps the global registration, as in autoplan()).
    const Stopwatch t;
    const auto local = autoplan_stages::local_registration(mesh, plane, out.defect, global, params);
    if (local)
      run(recorded(commands::register_mirror(local->params), to_json(local->result), t.ms()));
  }
  if (!step_complete(s.state(), kMirrorStep)) run(commands::complete_step(kMirrorStep));
  run(commands::complete_step(kClipStep));
  // The model's file read once: the model used is the one whose hash is recorded.
  std::optional<ShapeModel> model;
  std::string model_sha;
  if (!shape_model.empty()) {
    const std::string bytes = read_file_bytes(shape_model);
    model_sha = sha256_hex(bytes);
    model = parse_shape_model(bytes, shape_model);
  }
  Command propose =
      commands::propose_markers(params.propose, shape_model, model_sha, params.shape_prior);
  if (out.defect.found() && s.state().mirrored) {
    // The proposal's search is the detection, the shape model's fit and the markers.
    const Stopwatch t;
    const PlanState& st = s.state();
    const MarkerProposal markers =
        autoplan_stages::markers(out.defect, mesh, bone, st.mirrored->locator, params,
                                 st.next_marker_id, model ? &*model : nullptr);
    propose = recorded(std::move(propose), proposal_result(markers), detect_ms + t.ms());
  }
  run(std::move(propose));
  if (s.state().markers.empty()) {
    out.status = AutoplanSession::Status::NoDefect;
    return stop(s.state().message);
  }
  ImplantParams implant = params.implant;
  if (implant.tabs.any() && !implant.tabs.midline) implant.tabs.midline = plane;
  run(commands::build_implant(implant));
  if (!s.state().implant) return stop(s.state().message);
  run(commands::complete_step(kSmoothStep));
  if (!export_path.empty() && !run(commands::export_implant(export_path))) return out;
  out.status = AutoplanSession::Status::Planned;
  out.message = s.state().proposal_message;
  return out;
}

}  // namespace cranioplan
