#include "cranioplan/sessions/plan_state.h"

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "cranioplan/algorithms/alignment/mirror_mesh.h"
#include "cranioplan/algorithms/implant/smooth_markers.h"
#include "cranioplan/algorithms/implant/snap_markers.h"
#include "cranioplan/algorithms/io/file_io.h"
#include "cranioplan/algorithms/io/load_skull.h"
#include "cranioplan/algorithms/io/read_volume.h"
#include "cranioplan/algorithms/io/write_3mf.h"
#include "cranioplan/algorithms/io/write_mesh.h"
#include "cranioplan/algorithms/planning/propose_markers.h"
#include "cranioplan/algorithms/planning/shape_prior.h"
#include "cranioplan/algorithms/quality/ct_agreement.h"
#include "cranioplan/algorithms/shape/shape_model.h"
#include "cranioplan/sessions/marker_files.h"
#include "cranioplan/sessions/session_error.h"
#include "cranioplan/sessions/sha256.h"

namespace cranioplan {

SharedSurface::SharedSurface(const std::string& path, const ExtractBoneSurfaceParams& import)
    : loaded(load_skull(path, import)),
      mesh(loaded.mesh),
      locator(mesh),
      path(path),
      import(import) {}

ImplantData::ImplantData(ImplantResult result, std::shared_ptr<const SkullInput> skull,
                         QualityParams quality_params)
    : result_(std::move(result)),
      skull_(std::move(skull)),
      quality_params_(std::move(quality_params)) {}

const std::string& ImplantData::stl_sha256() const {
  std::call_once(sha_once_, [this] {
    // As exported: in the coordinates the skull's file gave (export_bytes).
    const MeshSpace space = skull_ ? skull_->surface->loaded.file_space : MeshSpace::Undeclared;
    stl_sha256_ = sha256_hex(encode_mesh(result_.mesh, MeshFormat::BinarySTL, space));
  });
  return stl_sha256_;
}

const QualityReport& ImplantData::quality() const {
  std::call_once(quality_once_, [this] {
    quality_ = skull_ ? check_implant(result_.mesh, &skull_->surface->mesh,
                                      &skull_->surface->locator, quality_params_)
                      : check_implant(result_.mesh, nullptr, quality_params_);
  });
  return quality_;
}

RigidTransform PlanState::mirror_transform() const {
  const RigidTransform reg =
      registration && registration->usable() ? registration->transform : RigidTransform{};
  return manual * reg;
}

const Marker* PlanState::find_marker(int id) const {
  for (const auto& m : markers)
    if (m.id == id) return &m;
  return nullptr;
}

std::optional<AttachedCt> plan_ct(const PlanState& s) {
  if (s.ct) return s.ct;
  if (!s.skull || s.skull->surface->loaded.source_kind != SkullSource::Volume) return std::nullopt;
  AttachedCt ct;
  ct.path = s.skull->surface->path;
  ct.recorded_path = s.skull->path;
  ct.sha256 = s.skull->sha256;
  ct.import = s.skull->surface->import;
  ct.message = "the CT the skull was imported from";
  return ct;
}

const std::array<WizardStep, kStepCount>& wizard_steps() {
  static const std::array<WizardStep, kStepCount> steps = {{
      {kLoadStep, "Load skull",
       "Open the patient's skull: a surface mesh (STL, PLY, OBJ, OFF, VTK, VTP) or a CT "
       "(InVesalius .inv3, NRRD, NIfTI, DICOM folder), which is turned into a bone surface at "
       "step 1's threshold (automatic: 300 HU for a CT, 0.5 for a mask). Done when a skull is "
       "loaded."},
      {kPlaneStep, "Landmarks and midsagittal plane",
       "Click the nasion and the centres of the left and right orbits (optional: points on the "
       "midline), then press Fit: the plane is refined from the landmarks and the skull's "
       "symmetry. Adjust it by hand if needed. Done when a plane is set."},
      {kMirrorStep, "Mirror and register",
       "Mirror the skull across the plane, then Register: the mirror (green) is fitted onto the "
       "healthy bone (whole skull or a region). Nudge it by hand if needed. Done when the mirror "
       "is registered (or accepted as it is)."},
      {kClipStep, "Clip and inspect",
       "Move the clip plane through the defect to see its inner edge and the mirrored bone that "
       "will fill it. Press Done when you have seen enough."},
      {kEdgeMarkersStep, "Edge markers",
       "Place outer edge markers (key 0) along the outer rim of the defect on the skull, and "
       "optionally inner edge markers (key 1) along its inner rim — or press Propose to place "
       "them automatically and edit them. Green: edge markers; magenta: surface markers "
       "(spheres outer, cubes inner); an orange line: a stretch of the rim no ray saw. Done "
       "with at least 3 outer edge markers (and either no inner edge markers or at least 3)."},
      {kSurfaceMarkersStep, "Surface markers",
       "Place outer surface markers (key 2) and inner surface markers (key 3) on the mirrored "
       "skull inside the defect (a proposal also places some on the intact bone around it, "
       "where the implant must meet the skull's curve). Done with at least 3 outer surface "
       "markers."},
      {kBuildStep, "Build implant",
       "Build the implant (the defaults are the automatic plan's: a shell fitted to the bone); "
       "or choose the method (shell: smooth fitted surfaces, or Delaunay 3D as in Egger et al. "
       "2017), the material, holes and tabs first. Done when an implant is built that the "
       "quality check passes."},
      {kSmoothStep, "Smooth and refine",
       "Smooth the surface markers (radius, edge-marker weight; edge markers stay fixed) and "
       "move markers where needed: the implant follows. Press Done when satisfied."},
      {kExportStep, "Check and export",
       "Read the quality report (watertight, thickness, gap to bone, overlap) and export the "
       "implant as STL, PLY or 3MF (with a casting mould if wanted); the surgeon approves it. "
       "Done when the current implant has been exported."},
  }};
  return steps;
}

namespace {

int count_type(const PlanState& s, MarkerType t) {
  int n = 0;
  for (const auto& m : s.markers) n += m.type == t;
  return n;
}

bool fail(std::string* out, const std::string& why) {
  if (out) *out = why;
  return false;
}

}  // namespace

std::string describe_plane_fit(const PlaneFit& fit) {
  const double rms = fit.symmetry_rms_mm, inliers = fit.inlier_fraction;
  const char* verdict =
      rms <= 1.5 && inliers >= 0.6 ? "good: the two sides agree as a normal skull's do"
      : rms <= 3.0 && inliers >= 0.4
          ? "fair: check the plane on the face (nose and between the eyes) before going on"
          : "poor: place the landmarks again, or adjust the plane by hand";
  const char* start = fit.initial_method == "landmarks"   ? "started from the landmarks"
                      : fit.initial_method == "automatic" ? "started from the skull's symmetry"
                                                          : fit.initial_method.c_str();
  char buf[360];
  std::snprintf(buf, sizeof(buf), "symmetry RMS %.2f mm, %.0f%% inliers (%s) — %s", rms,
                100.0 * inliers, start, verdict);
  return buf;
}

const char* registration_verdict(const RegisterResult& r) {
  if (r.rms_mm <= 1.5 && r.inlier_fraction >= 0.6)
    return "good: the mirror lies on the healthy bone";
  if (r.rms_mm <= 3.0 && r.inlier_fraction >= 0.4)
    return "fair: look at the mirror on the healthy side, or register on a region near the "
           "defect";
  return "poor: check the plane (step 2), or nudge the mirror by hand and register again";
}

std::string landmark_words(const std::string& name) {
  if (name == "orbit_left") return "left orbit";
  if (name == "orbit_right") return "right orbit";
  if (name == "midline") return "midline";
  return name;  // nasion
}

bool step_complete(const PlanState& s, int step, std::string* missing) {
  switch (step) {
    case kLoadStep:
      return s.skull ? true : fail(missing, "load a skull");
    case kPlaneStep:
      return s.plane ? true : fail(missing, "fit the midsagittal plane (or set it by hand)");
    case kMirrorStep:
      if (!s.mirrored) return fail(missing, "mirror the skull");
      if ((s.registration && s.registration->usable()) || s.acknowledged[kMirrorStep]) return true;
      return fail(missing, "register the mirrored skull (or accept it as it is)");
    case kClipStep:
      return s.acknowledged[kClipStep] ? true : fail(missing, "inspect the defect and press Done");
    case kEdgeMarkersStep: {
      const int outer = count_type(s, MarkerType::OuterEdge);
      const int inner = count_type(s, MarkerType::InnerEdge);
      if (outer < 3)
        return fail(missing,
                    "place at least 3 outer edge markers (" + std::to_string(outer) + " so far)");
      if (inner > 0 && inner < 3)
        return fail(missing, "inner edge markers: " + std::to_string(inner) +
                                 " placed; place at least 3, or none (the inner rim then "
                                 "follows the bone thickness)");
      return true;
    }
    case kSurfaceMarkersStep: {
      const int outer = count_type(s, MarkerType::OuterSurface);
      return outer >= 3 ? true
                        : fail(missing, "place at least 3 outer surface markers (" +
                                            std::to_string(outer) + " so far)");
    }
    case kBuildStep:
      if (s.implant && s.implant->result().usable()) return true;
      return fail(missing, s.implant_params ? "the implant could not be built: " + s.message
                                            : std::string("build the implant"));
    case kSmoothStep:
      return s.acknowledged[kSmoothStep]
                 ? true
                 : fail(missing, "review the markers and implant, press Done");
    case kExportStep:
      for (const auto& e : s.exports)
        if (s.implant && e.implant_sha256 == s.implant->stl_sha256()) return true;
      return fail(missing, "export the implant");
    default:
      return fail(missing, "there is no step " + std::to_string(step));
  }
}

bool step_unlocked(const PlanState& s, int step, std::string* why) {
  for (int k = kLoadStep; k < step && k <= kStepCount; ++k) {
    std::string missing;
    if (!step_complete(s, k, &missing))
      return fail(why, "step " + std::to_string(step) + " (" + wizard_steps()[step - 1].title +
                           ") is locked: step " + std::to_string(k) + " (" +
                           wizard_steps()[k - 1].title + ") is not done — " + missing);
  }
  return true;
}

int command_step(const PlanState& s, const Command& c) {
  auto marker_step = [](MarkerType t) -> int {
    return is_edge(t) ? kEdgeMarkersStep : kSurfaceMarkersStep;
  };
  const Json& p = c.params;
  switch (c.type) {
    case CommandType::LoadSkull:
      return kLoadStep;
    case CommandType::SetLandmark:
    case CommandType::ClearLandmark:
    case CommandType::FitPlane:
    case CommandType::AdjustPlane:
      return kPlaneStep;
    case CommandType::Mirror:
    case CommandType::Register:
    case CommandType::MoveMirrored:
      return kMirrorStep;
    case CommandType::SetClipPlane:
      return kClipStep;
    case CommandType::AddMarker:
      return marker_step(static_cast<MarkerType>(std::clamp(p.value("type", 0), 0, 3)));
    case CommandType::MoveMarker:
    case CommandType::DeleteMarker:
    case CommandType::RetypeMarker: {
      const Marker* m = s.find_marker(p.value("id", -1));
      int step = m ? marker_step(m->type) : kEdgeMarkersStep;
      if (c.type == CommandType::RetypeMarker)
        step = std::max(step,
                        marker_step(static_cast<MarkerType>(std::clamp(p.value("type", 0), 0, 3))));
      return step;
    }
    case CommandType::ImportMarkers:
    case CommandType::ClearMarkers:
    case CommandType::ProposeMarkers:
      return kEdgeMarkersStep;
    case CommandType::BuildImplant:
      return kBuildStep;
    case CommandType::SmoothMarkers:
      return kSmoothStep;
    case CommandType::ExportImplant:
      return kExportStep;
    case CommandType::GoToStep:
    case CommandType::CompleteStep:
      return std::clamp(p.value("step", 1), static_cast<int>(kLoadStep), kStepCount);
    case CommandType::Approve:
      return kExportStep;
    case CommandType::Note:
    case CommandType::AttachCt:
      return 0;
  }
  return 0;
}

namespace {

// ----- derived results ---------------------------------------------------------------------

void unacknowledge(PlanState& s, int step, const std::string& why) {
  if (!s.acknowledged[step]) return;
  s.acknowledged[step] = false;
  s.stale[step] = why;
}

void update_mirrored(PlanState& s, const std::string& why) {
  if (!s.mirror_requested || !s.plane) {
    s.mirrored.reset();
    return;
  }
  // The mirror is always the skull reflected across the current plane (plane_changed registers
  // it again), so it is the skull moved: no mesh, no second tree.
  const RigidTransform placement = s.mirror_transform() * reflection_across(*s.plane);
  s.mirrored = std::make_shared<const MovedSurface>(
      MovedSurface{s.skull->surface, placement, s.skull->surface->locator.moved(placement)});
  unacknowledge(s, kClipStep, why);
  for (const auto& m : s.markers)
    if (m.surface == MarkerSurface::Mirrored) {
      s.stale[kSurfaceMarkersStep] =
          why + ": surface markers were placed on the mirror before it moved";
      break;
    }
}

// Registers the mirror with s.register_params, or applies `recorded` (what the command that
// caused it recorded when it was first done) so that a replay gives the same registration
// whatever later versions do to ICP. What was computed is put in `*record` when given. False
// when the attempt failed and the previous (working) registration was kept.
bool run_registration(PlanState& s, const Json* recorded = nullptr, Json* record = nullptr,
                      const std::string& where = "") {
  RegisterResult result =
      recorded ? register_result_from_json(*recorded, where)
               : register_mirror(s.skull->surface->mesh, *s.plane, *s.register_params);
  if (!recorded && record) *record = to_json(result);
  if (!result.usable() && s.registration && s.registration->usable()) {
    // A failed attempt does not throw away a working registration.
    s.message = "registration failed: " + result.message + "; the previous registration is kept";
    return false;
  }
  s.registration = std::move(result);
  s.manual = RigidTransform{};
  char buf[320];
  if (s.registration->usable())
    std::snprintf(buf, sizeof(buf),
                  "registered: RMS %.2f mm, %.0f%% of samples paired, %d iterations — %s",
                  s.registration->rms_mm, 100.0 * s.registration->inlier_fraction,
                  s.registration->iterations, registration_verdict(*s.registration));
  else
    std::snprintf(buf, sizeof(buf), "registration failed: %s", s.registration->message.c_str());
  s.message = buf;
  return true;
}

void rebuild_implant(PlanState& s) {
  if (!s.implant_params) return;
  ImplantParams p = *s.implant_params;
  if (!p.radial_center && s.defect_center) p.radial_center = s.defect_center;
  if (p.scan_ends.empty()) p.scan_ends = s.scan_ends;
  auto built = std::make_shared<const ImplantData>(
      [&] {
        return build_implant(s.markers, &s.skull->surface->mesh, &s.skull->surface->locator, p);
      },
      [&](const ImplantResult& r) { return quality_params_for(p, r); }, s.skull);
  const ImplantResult& r = built->result();
  if (r.usable()) {
    char buf[160];
    std::snprintf(buf, sizeof(buf), "implant built: %s triangles, %s",
                  format_count(static_cast<long long>(r.mesh.n_faces())).c_str(),
                  r.watertight ? "watertight" : "not watertight");
    s.message = buf;
    s.implant = std::move(built);
  } else {
    s.message = "implant not built: " + r.message;
    s.implant.reset();
  }
}

void markers_changed(PlanState& s) {
  unacknowledge(s, kSmoothStep, "the markers changed");
  rebuild_implant(s);
}

// After the plane changed, the mirror is recomputed and, when it had been registered,
// registered again; that registration is recorded in the command as "registration" (and
// applied from there on replay) when `record` is given.
void plane_changed(PlanState& s, const ParamReader* r = nullptr, Json* record = nullptr) {
  unacknowledge(s, kClipStep, "the plane changed");
  if (!s.mirror_requested) return;
  std::string why = "the plane changed: mirror recomputed";
  if (s.register_params) {
    const std::string plane_message = s.message;
    const bool recorded = r && r->has("registration");
    Json computed;
    run_registration(s, recorded ? &r->value("registration") : nullptr,
                     record ? &computed : nullptr, r ? r->where() + " registration" : "");
    if (record && !recorded) (*record)["registration"] = computed;
    why += " and registered again";
    s.message = plane_message + "; " + s.message;
  }
  s.stale[kMirrorStep] = why;
  update_mirrored(s, "the plane changed");
}

const SurfaceLocator* surface_for(const PlanState& s, MarkerSurface surface) {
  if (surface == MarkerSurface::Mirrored && s.mirrored) return &s.mirrored->locator;
  return &s.skull->surface->locator;
}

// Snaps markers onto their surfaces; false (with the reason) when one is too far away.
bool snap(const PlanState& s, std::vector<Marker>& markers, std::string& why) {
  const SnapMarkersResult r =
      snap_markers(markers, s.skull->surface->locator, s.mirrored ? &s.mirrored->locator : nullptr);
  if (r.status != SnapMarkersResult::Status::Snapped) {
    why = r.message;
    return false;
  }
  markers = r.markers;
  return true;
}

std::string resolve_input(const std::string& recorded, const ApplyContext& ctx,
                          const char* what = "skull file") {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(recorded, ec)) return recorded;
  if (!ctx.session_dir.empty()) {
    for (const fs::path& candidate : {fs::path(ctx.session_dir) / recorded,
                                      fs::path(ctx.session_dir) / fs::path(recorded).filename()})
      if (fs::exists(candidate, ec)) return candidate.string();
  }
  throw InputError(recorded, std::string("the ") + what + " of this plan is missing");
}

struct Refusal {
  std::string message;
};

// ----- the commands ----------------------------------------------------------------------------

// What the skull's file held and what the reading did about it (the load's warnings: the
// openings and how the inside is taken through them, pieces dropped, non-manifold edges, an
// inward winding turned), recorded when the command is first done. A replay reads the file
// again, repairs it the same way (the import's parameters are in the command), and says so
// when it finds the input otherwise than recorded. The file's path is left out of the warnings
// so a session moved with its skull compares equal.
Json input_report(const LoadedSkull& loaded, const SkullMesh& mesh, const std::string& path) {
  Json warnings = Json::array();
  for (std::string w : loaded.warnings) {
    if (w.rfind(path + ": ", 0) == 0) w = w.substr(path.size() + 2);
    warnings.push_back(w);
  }
  return Json{{"triangles", static_cast<long long>(mesh.n_faces())},
              {"pieces_dropped", loaded.pieces_dropped},
              {"warnings", warnings}};
}

void apply_load(PlanState& s, const ParamReader& r, const ApplyContext& ctx, Json& record) {
  const std::string recorded = r.string("path");
  const std::string path = resolve_input(recorded, ctx);
  const std::string sha = sha256_file(path);  // the bytes go before the mesh comes
  const std::string expected = r.string("sha256");
  if (sha != expected)
    throw SessionError(
        path, "the skull file changed since this plan was made (SHA-256 " + sha.substr(0, 12) +
                  "… now, " +
                  (expected.empty() ? std::string("none") : expected.substr(0, 12) + "…") +
                  " recorded)");
  ExtractBoneSurfaceParams import;
  params_from_json(ParamReader(r.value("import"), r.where() + " import"), import);
  auto input = std::make_shared<SkullInput>();
  input->surface = std::make_shared<const SharedSurface>(path, import);
  const LoadedSkull& loaded = input->surface->loaded;
  input->path = recorded;
  input->sha256 = sha;
  const SkullMesh& mesh = input->surface->mesh;
  input->centroid = vertex_centroid(mesh);
  PlanState fresh;
  fresh.notes = s.notes;
  fresh.skull = std::move(input);
  fresh.current_step = kPlaneStep;
  fresh.message = "loaded " + loaded.description + ": " +
                  format_count(static_cast<long long>(fresh.skull->surface->mesh.n_faces())) +
                  " triangles";
  if (!loaded.frame.empty()) fresh.message += "; patient frame: " + loaded.frame;
  for (const std::string& w : loaded.warnings) fresh.message += "; " + w;
  for (const std::string& n : loaded.notes) fresh.message += "; " + n;
  const Json report = input_report(loaded, fresh.skull->surface->mesh, path);
  const Json recorded_report = r.has("input_report") ? r.value("input_report") : Json();
  if (!recorded_report.is_object())
    record["input_report"] = report;
  else if (recorded_report != report)
    fresh.message += "; the file reads otherwise than when this plan was made (recorded: " +
                     std::to_string(recorded_report.value("triangles", 0LL)) + " triangles, " +
                     std::to_string(recorded_report.value("warnings", Json::array()).size()) +
                     " warnings; now " + std::to_string(report["triangles"].get<long long>()) +
                     " and " + std::to_string(report["warnings"].size()) + ")";
  s = std::move(fresh);
}

// A landmark is put on the skull's surface; one further from it than this is refused, mm. An
// orbit's centre given in space (a file's) lies up to about 20 mm from the bone around it; a
// file in another frame (RAS read as LPS) puts landmarks a hundred millimetres off.
constexpr double kMaxLandmarkSnapMm = 25.0;

// The CT of a plan made from a mesh: the file must be the one recorded, and its bone surface at
// the threshold given must lie on the skull (ct_agreement), measured once and recorded.
void apply_attach_ct(PlanState& s, const ParamReader& r, const ApplyContext& ctx, Json& record) {
  if (!s.skull) throw Refusal{"load a skull before attaching its CT"};
  const std::string recorded = r.string("path");
  const std::string path = resolve_input(recorded, ctx, "CT");
  const std::string sha = sha256_file(path);
  if (sha != r.string("sha256"))
    throw SessionError(
        path, "the CT changed since it was attached (SHA-256 " + sha.substr(0, 12) + "… now)");
  AttachedCt ct;
  ct.path = path;
  ct.recorded_path = recorded;
  ct.sha256 = sha;
  params_from_json(ParamReader(r.value("import"), r.where() + " import"), ct.import);
  if (r.has("result")) {
    const Json& j = r.value("result");
    ct.median_mm = j.at("median_mm").get<double>();
    ct.p90_mm = j.at("p90_mm").get<double>();
    ct.message = j.at("message").get<std::string>();
  } else {
    ReadVolumeParams read;
    read.dicom_series = ct.import.dicom_series;
    read.patient_frame = ct.import.patient_frame;
    const Volume volume = read_volume(path, read);
    CtAgreementParams check;
    check.surface = ct.import;
    const CtAgreement a = ct_agreement(s.skull->surface->mesh, volume, check);
    if (!a.agrees) throw Refusal{path + ": " + a.message};
    ct.median_mm = a.median_mm;
    ct.p90_mm = a.p90_mm;
    ct.message = a.message;
    record["result"] =
        Json{{"median_mm", a.median_mm}, {"p90_mm", a.p90_mm}, {"message", a.message}};
  }
  s.message = "attached the CT " + recorded + ": " + ct.message;
  s.ct = std::move(ct);
}

void apply_landmark(PlanState& s, const ParamReader& r, bool set) {
  const std::string name = r.string("name");
  std::optional<Eigen::Vector3d> value;
  if (set) {
    // Clicked landmarks lie on the skull; one from a file far from it is in another frame.
    const auto closest = s.skull->surface->locator.closest(r.vector3("position"));
    if (closest.distance > kMaxLandmarkSnapMm) {
      char buf[200];
      std::snprintf(buf, sizeof(buf),
                    "the %s landmark lies %.1f mm from the skull (at most %.0f mm): is it in the "
                    "skull's frame?",
                    name.c_str(), closest.distance, kMaxLandmarkSnapMm);
      throw Refusal{buf};
    }
    value = closest.point;
  }
  if (name == "nasion")
    s.landmarks.nasion = value;
  else if (name == "orbit_left")
    s.landmarks.orbit_left = value;
  else if (name == "orbit_right")
    s.landmarks.orbit_right = value;
  else if (name == "midline") {
    if (set)
      s.landmarks.midline.push_back(*value);
    else
      s.landmarks.midline.clear();
  } else {
    throw Refusal{"unknown landmark \"" + name + "\" (nasion, orbit_left, orbit_right or midline)"};
  }
  s.message =
      set ? "placed the " + landmark_words(name) + " landmark"
          : "cleared the " + landmark_words(name) + " landmark" + (name == "midline" ? "s" : "");
}

// Fits the plane, or applies the fit the command recorded when it was first done (version 2),
// so a replay gives the same plane whatever later versions do to the fit.
void apply_fit_plane(PlanState& s, const ParamReader& r, int version, Json& record) {
  Json recorded = r.value("params");
  // Version 1 (before the coarse start) refined at one robust scale throughout.
  if (version < 2 && recorded.is_object() && !recorded.contains("coarse_iterations")) {
    recorded["coarse_iterations"] = 0;
    recorded["coarse_robust_scale_mm"] = recorded.value("robust_scale_mm", 1.0);
  }
  PlaneFitParams params;
  params_from_json(ParamReader(recorded, r.where() + " params"), params);
  PlaneFit fit;
  if (r.has("result")) {
    fit = plane_fit_from_json(r.value("result"), r.where() + " result");
  } else {
    fit = fit_sagittal_plane(s.skull->surface->mesh, s.landmarks, params);
    if (version >= 2) record["result"] = to_json(fit);
  }
  s.plane_fit = fit;
  if (!fit.usable()) {
    s.message = "plane fit failed: " + fit.message;
    return;
  }
  s.plane = fit.plane;
  s.message = "plane fitted: " + describe_plane_fit(fit);
  plane_changed(s, version >= 2 ? &r : nullptr, version >= 2 ? &record : nullptr);
}

void apply_adjust_plane(PlanState& s, const ParamReader& r, int version, Json& record) {
  if (!s.plane) throw Refusal{"there is no plane to adjust yet: fit it first"};
  const Eigen::Vector3d axis = r.vector3("axis");
  const double angle = r.number("angle_deg");
  const double shift = r.number("shift_mm");
  if (!std::isfinite(angle) || !std::isfinite(shift))
    throw Refusal{"angle and shift must be numbers"};
  if (angle != 0.0 && axis.norm() < 1e-9) throw Refusal{"the rotation axis has no direction"};
  const Eigen::Vector3d pivot = s.plane->project(s.skull->centroid);
  Eigen::Vector3d normal = s.plane->normal;
  if (angle != 0.0) normal = Eigen::AngleAxisd(angle * M_PI / 180.0, axis.normalized()) * normal;
  s.plane = Plane::through(pivot + shift * normal.normalized(), normal);
  s.message = "plane adjusted by hand";
  plane_changed(s, version >= 2 ? &r : nullptr, version >= 2 ? &record : nullptr);
}

void apply_mirror(PlanState& s) {
  if (!s.plane) throw Refusal{"fit the midsagittal plane before mirroring the skull"};
  s.mirror_requested = true;
  s.registration.reset();
  s.register_params.reset();
  s.manual = RigidTransform{};
  s.message = "skull mirrored across the plane";
  update_mirrored(s, "the mirror was made again");
}

// Registers the mirror, or (version 2) applies the registration the command recorded.
void apply_register(PlanState& s, const ParamReader& r, int version, Json& record) {
  if (!s.mirror_requested) throw Refusal{"mirror the skull before registering it"};
  RegisterParams params;
  params_from_json(ParamReader(r.value("params"), r.where() + " params"), params);
  const std::optional<RegisterParams> previous = s.register_params;
  s.register_params = params;
  const bool recorded = r.has("result");
  Json computed;
  const bool registered =
      run_registration(s, recorded ? &r.value("result") : nullptr,
                       version >= 2 ? &computed : nullptr, r.where() + " result");
  if (version >= 2 && !recorded) record["result"] = computed;
  if (!registered) {
    s.register_params = previous;
    return;
  }
  update_mirrored(s, "the mirror was registered again");
}

void apply_move_mirrored(PlanState& s, const ParamReader& r) {
  if (!s.mirror_requested) throw Refusal{"mirror the skull before moving the mirror"};
  const Eigen::Vector3d axis = r.vector3("axis");
  const double angle = r.number("angle_deg");
  const Eigen::Vector3d center = r.vector3("center");
  const Eigen::Vector3d translation = r.vector3("translation");
  if (!std::isfinite(angle)) throw Refusal{"the angle must be a number"};
  if (angle != 0.0 && axis.norm() < 1e-9) throw Refusal{"the rotation axis has no direction"};
  RigidTransform turn;
  if (angle != 0.0) turn = RigidTransform::from_axis_angle(axis, angle, Eigen::Vector3d::Zero());
  // x ↦ R(x − c) + c + t
  RigidTransform delta;
  delta.rotation = turn.rotation;
  delta.translation = center - turn.rotation * center + translation;
  s.manual = delta * s.manual;
  s.message = "mirrored skull moved by hand";
  update_mirrored(s, "the mirror was moved by hand");
}

void apply_clip(PlanState& s, const ParamReader& r) {
  if (r.boolean("enabled")) {
    s.clip_plane = plane_from_json(r.value("plane"), r.where());
    s.message = "clip plane set";
  } else {
    s.clip_plane.reset();
    s.message = "clip plane removed";
  }
}

MarkerType marker_type(const ParamReader& r) {
  const int t = r.integer("type");
  if (t < 0 || t > 3) throw Refusal{"marker type must be 0..3, not " + std::to_string(t)};
  return static_cast<MarkerType>(t);
}

Marker& marker_ref(PlanState& s, const ParamReader& r) {
  const int id = r.integer("id");
  for (auto& m : s.markers)
    if (m.id == id) return m;
  throw Refusal{"there is no marker " + std::to_string(id)};
}

void snap_one(const PlanState& s, Marker& m) {
  m.position = surface_for(s, m.surface)->closest(m.position).point;
}

void apply_marker_edit(PlanState& s, CommandType type, const ParamReader& r) {
  switch (type) {
    case CommandType::AddMarker: {
      Marker m;
      m.type = marker_type(r);
      m.surface = default_surface(m.type);
      m.position = r.vector3("position");
      m.id = s.next_marker_id++;
      snap_one(s, m);
      s.markers.push_back(m);
      s.message = "added marker " + std::to_string(m.id);
      break;
    }
    case CommandType::MoveMarker: {
      Marker& m = marker_ref(s, r);
      m.position = r.vector3("position");
      snap_one(s, m);
      s.message = "moved marker " + std::to_string(m.id);
      break;
    }
    case CommandType::DeleteMarker: {
      const int id = marker_ref(s, r).id;
      s.markers.erase(std::remove_if(s.markers.begin(), s.markers.end(),
                                     [id](const Marker& m) { return m.id == id; }),
                      s.markers.end());
      s.message = "deleted marker " + std::to_string(id);
      break;
    }
    case CommandType::RetypeMarker: {
      Marker& m = marker_ref(s, r);
      m.type = marker_type(r);
      m.surface = default_surface(m.type);
      snap_one(s, m);
      s.message = "marker " + std::to_string(m.id) + " is now " + to_string(m.type);
      break;
    }
    case CommandType::ImportMarkers: {
      std::vector<Marker> imported = markers_from_json(r.value("markers"), r.where());
      std::string why;
      if (!snap(s, imported, why)) throw Refusal{"imported markers: " + why};
      for (auto& m : imported) {
        m.id = s.next_marker_id++;
        s.markers.push_back(m);
      }
      s.message = "imported " + std::to_string(imported.size()) + " markers";
      break;
    }
    case CommandType::ClearMarkers:
      s.markers.clear();
      s.message = "markers cleared";
      break;
    default:
      assert(false && "not a marker edit");
  }
  markers_changed(s);
}

// Applies a propose_markers command's result; false when it says nothing was proposed
// (s.message says why).
bool apply_proposal_result(PlanState& s, const Json& j, const std::string& where) {
  const ParamReader result(j, where);
  if (!result.boolean("proposed")) {
    s.message = result.string("message");
    return false;
  }
  s.markers = markers_from_json(Json{{"markers", result.value("markers")}}, where);
  s.defect_center.reset();
  if (!result.value("defect_center").is_null()) s.defect_center = result.vector3("defect_center");
  s.proposal_message = result.string("message");
  // Results recorded by older plans may have none.
  s.scan_ends.clear();
  if (result.has("scan_ends")) s.scan_ends = planes_from_json(result.value("scan_ends"), where);
  s.unseen_rim.clear();
  if (result.has("unseen_rim")) {
    const Json& stretches = result.value("unseen_rim");
    if (!stretches.is_array())
      throw SessionError(where, "'unseen_rim' must be a list of stretches");
    for (size_t k = 0; k < stretches.size(); ++k) {
      const ParamReader one(stretches[k], where + " unseen_rim[" + std::to_string(k) + "]");
      s.unseen_rim.push_back({one.vector3("from"), one.vector3("to")});
    }
  }
  return true;
}

// How the model a propose_markers command names was fitted and weighed, as recorded: version 7
// recorded neither and is read with what it was made with (weight 0.5, 10 mm margin, 1 mm
// noise, a poor fit over 1.0 mm or under half paired).
void recorded_prior(const ParamReader& r, ProposeParams& params, ShapePriorParams& prior) {
  const ParamReader model(r.value("shape_model"), r.where() + " shape_model");
  auto number_or = [&](const char* name, double version7) {
    return model.has(name) ? model.number(name) : version7;
  };
  params.shape_model_weight = number_or("weight", 0.5);
  prior.margin_mm = number_or("margin_mm", 10.0);
  prior.fit.noise_mm = number_or("noise_mm", 1.0);
  prior.fit.max_rms_mm = number_or("max_rms_mm", 1.0);
  prior.fit.min_paired = number_or("min_paired", 0.5);
}

// The shape model a propose_markers command names, read once and checked against its recorded
// SHA-256 (a SessionError naming the file when it changed).
ShapeModel recorded_shape_model(const ParamReader& r, const ApplyContext& ctx) {
  const ParamReader model(r.value("shape_model"), r.where() + " shape_model");
  const std::string path = resolve_input(model.string("path"), ctx, "shape model");
  const std::string bytes = read_file_bytes(path);
  const std::string sha = sha256_hex(bytes), expected = model.string("sha256");
  if (sha != expected)
    throw SessionError(path, "the shape model changed since this plan was made (SHA-256 " +
                                 sha.substr(0, 12) + "… now, " + expected.substr(0, 12) +
                                 "… recorded)");
  return parse_shape_model(bytes, path);
}

// What a proposal made again is asked: the recorded parameters of a proposal of this version;
// of an earlier version (read with the switches that replay it as it was made), today's, with
// its model's weight.
ProposeParams asked_again(const ProposeParams& recorded, int version) {
  if (version == current_version(CommandType::ProposeMarkers)) return recorded;
  ProposeParams today;
  today.shape_model_weight = recorded.shape_model_weight;
  return today;
}

// Proposes markers, or applies the proposal the command recorded when it was first done; both
// go through the recorded form, so a replay is the live command. A proposal replaces the
// markers; a failed one leaves them as they were.
void apply_propose(PlanState& s, const ParamReader& r, int version, const ApplyContext& ctx,
                   Json& record) {
  ProposeParams params;
  params_from_json(ParamReader(r.value("params"), r.where() + " params"), params);
  ShapePriorParams prior;
  if (r.has("shape_model")) recorded_prior(r, params, prior);
  const ProposeParams asked = asked_again(params, version);
  if (!r.has("result")) {
    take_scan_borders(params.detect, s.skull->surface->loaded.report);
    const SurfaceLocator& bone = s.skull->surface->locator;
    const SurfaceLocator& mirror = s.mirrored ? s.mirrored->locator : bone;
    if (r.has("shape_model")) {
      const ShapeModel model = recorded_shape_model(r, ctx);
      const DefectRegion defect =
          detect_defect_near_plane(s.skull->surface->mesh, bone, *s.plane, params.detect);
      record["result"] = proposal_result(propose_markers_with_model(
          defect, s.skull->surface->mesh, bone, mirror, params, s.next_marker_id, &model, prior));
    } else {
      record["result"] = proposal_result(propose_markers(s.skull->surface->mesh, bone, *s.plane,
                                                         mirror, params, s.next_marker_id));
    }
  }
  const Json& result = r.has("result") ? r.value("result") : record["result"];
  if (!apply_proposal_result(s, result, r.where() + " result")) return;
  s.proposal_params = asked;
  s.proposal_prior = prior;
  // Where the replay finds it (beside the session when moved with it); as recorded when gone.
  s.proposal_shape_model.clear();
  if (r.has("shape_model")) {
    const std::string recorded =
        ParamReader(r.value("shape_model"), r.where() + " shape_model").string("path");
    try {
      s.proposal_shape_model = resolve_input(recorded, ctx, "shape model");
    } catch (const InputError&) {
      s.proposal_shape_model = recorded;
    }
  }
  for (const auto& m : s.markers) s.next_marker_id = std::max(s.next_marker_id, m.id + 1);
  s.message = s.proposal_message;
  markers_changed(s);
}

void apply_smooth(PlanState& s, const ParamReader& r) {
  SmoothParams params;
  params_from_json(ParamReader(r.value("params"), r.where() + " params"), params);
  const bool project = r.boolean("project_onto_mirror");
  const SmoothResult result =
      smooth_markers(s.markers, params, project && s.mirrored ? &s.mirrored->locator : nullptr);
  if (result.status != SmoothResult::Status::Smoothed) {
    s.message = "markers not smoothed: " + result.message;
    return;
  }
  s.markers = result.markers;
  char buf[120];
  std::snprintf(buf, sizeof(buf), "markers smoothed: largest move %.2f mm", result.max_move_mm);
  s.message = buf;
  markers_changed(s);
  const std::string implant_message = s.message;
  if (implant_message != buf) s.message = std::string(buf) + "; " + implant_message;
}

void apply_build(PlanState& s, const ParamReader& r, int version) {
  Json recorded = r.value("params");
  // Version 1 (before fitting to the bone existed) built the shell without it.
  if (version < 2 && recorded.is_object() && !recorded.contains("fit_to_bone_mm"))
    recorded["fit_to_bone_mm"] = 0.0;
  ImplantParams params;
  params_from_json(ParamReader(recorded, r.where() + " params"), params);
  // Before version 8, tabs and holes were meshed without the iso-level gap.
  params.tabs.iso_gap = params.perforations.iso_gap = version >= 8;
  // Before version 9, holes were drilled along the outer normal, to below the inner surface
  // under their centre, and a tab's underside went nowhere deeper than 1.5 mm below the outer
  // table at the implant's edge.
  params.perforations.mid_normal = params.tabs.follow_implant = version >= 9;
  // Before version 10, the bridging of narrow gaps held a tab over the implant's rounded edge.
  params.tabs.on_implant_edge = version >= 10;
  // Before version 11, a rim point fitted to the bone stayed where the bone was first found,
  // and the fit was meshed without the iso-level gap.
  params.fit_reaches_the_bone = params.trim.iso_gap = version >= 11;
  // Before version 12, evenly placed tabs were placed once, whether they rested on the bone,
  // and every pattern hole was drilled, whatever corner its rim left.
  params.tabs.keep_on_bone = params.perforations.sound_rims = version >= 12;
  // Before version 13, the fit to the bone used the margin asked, whatever gap it left.
  params.fit_margin_search = version >= 13;
  // Before version 14, the shell fitted to the bone kept the surfaces' own thickness.
  params.fit_keeps_shell_thick = version >= 14;
  s.implant_params = params;
  unacknowledge(s, kSmoothStep, "the implant was built again");
  rebuild_implant(s);
}

}  // namespace

std::string plan_description(const std::string& plan_sha256, const std::string& implant_sha256) {
  return "Cranioplan plan SHA-256 " + plan_sha256 + "; implant STL SHA-256 " + implant_sha256;
}

MouldResult mould_of(const SkullMesh& implant, const SkullMesh* skull, const MouldParams& params) {
  const Eigen::Vector3d inside =
      skull ? vertex_centroid(*skull) : vertex_centroid(implant) - 80.0 * Eigen::Vector3d::UnitZ();
  return make_casting_mould(implant, inside, params);
}

std::string export_bytes(const PlanState& s, const ExportSpec& spec, std::string* why) {
  const ImplantData& implant = *s.implant;
  const SkullMesh& mesh = implant.result().mesh;
  // In the coordinates the skull's file gave: RAS where it declared so (LoadedSkull::file_space).
  const MeshSpace space = s.skull ? s.skull->surface->loaded.file_space : MeshSpace::Undeclared;
  if (spec.format != "3mf")
    return encode_mesh(mesh, spec.format == "stl" ? MeshFormat::BinarySTL : MeshFormat::BinaryPLY,
                       space);
  const std::vector<std::pair<std::string, std::string>> metadata = {
      {"Application", "Cranioplan"},
      {"Description", plan_description(spec.plan_sha256, implant.stl_sha256())}};
  const bool turn = negates_x_and_y(space);
  const SkullMesh turned = turn ? mesh_in_space(mesh, space) : SkullMesh();
  const SkullMesh& implant_out = turn ? turned : mesh;
  if (!spec.mould) return encode_3mf({{"implant", &implant_out}}, metadata);
  const MouldResult m = mould_of(mesh, s.skull ? &s.skull->surface->mesh : nullptr, *spec.mould);
  if (!m.usable()) {
    if (why) *why = "the mould could not be made: " + m.message;
    return {};
  }
  if (!turn)
    return encode_3mf({{"implant", &mesh}, {"mould outer", &m.outer}, {"mould inner", &m.inner}},
                      metadata);
  const SkullMesh outer = mesh_in_space(m.outer, space), inner = mesh_in_space(m.inner, space);
  return encode_3mf({{"implant", &implant_out}, {"mould outer", &outer}, {"mould inner", &inner}},
                    metadata);
}

namespace {

void apply_export(PlanState& s, const ParamReader& r, int version) {
  if (!s.implant) throw Refusal{"there is no implant to export: build it first"};
  ExportRecord e;
  e.path = r.string("path");
  e.format = r.string("format");
  if (e.format != "stl" && e.format != "ply" && e.format != "3mf")
    throw Refusal{"export format must be \"stl\", \"ply\" or \"3mf\", not \"" + e.format + "\""};
  e.recorded_sha256 = r.string("sha256");
  ExportSpec spec;
  spec.format = e.format;
  if (r.has("plan_sha256")) spec.plan_sha256 = r.string("plan_sha256");
  if (r.has("mould")) {
    spec.mould = mould_from_json(ParamReader(r.value("mould"), r.where() + " mould"));
    spec.mould->iso_gap = version >= 2;  // version 1 meshed the mould without the gap
  }
  std::string why;
  const std::string bytes = export_bytes(s, spec, &why);
  if (!why.empty()) throw Refusal{why};
  e.replayed_sha256 = sha256_hex(bytes);
  e.implant_sha256 = s.implant->stl_sha256();
  s.message = e.recorded_sha256 == e.replayed_sha256
                  ? "implant exported to " + e.path
                  : "implant exported to " + e.path +
                        " — but the implant now encodes to different bytes than were recorded";
  s.exports.push_back(std::move(e));
}

void apply_approve(PlanState& s, const ParamReader& r) {
  if (!s.implant) throw Refusal{"there is no implant to approve: build it first"};
  PlanState::Approval a{r.string("by"), r.string("role"), r.string("implant_sha256")};
  if (a.by.empty()) throw Refusal{"an approval names who approves"};
  if (a.implant_sha256 != s.implant->stl_sha256())
    throw Refusal{"the approval is of another implant (SHA-256 " + a.implant_sha256.substr(0, 12) +
                  "…) than this plan's"};
  s.approval = a;
  s.approval_withdrawn.clear();
  s.message = "implant approved by " + a.by + " (" + a.role + ")";
}

void apply_step(PlanState& s, CommandType type, const ParamReader& r) {
  const int step = r.integer("step");
  if (step < kLoadStep || step > kStepCount)
    throw Refusal{"there is no step " + std::to_string(step)};
  if (type == CommandType::GoToStep) {
    s.current_step = step;
    s.message = std::string("step ") + std::to_string(step) + ": " + wizard_steps()[step - 1].title;
    return;
  }
  std::string missing;
  const bool by_hand = step == kMirrorStep || step == kClipStep || step == kSmoothStep;
  if (step == kMirrorStep && !s.mirrored)
    throw Refusal{"step 3 cannot be done: mirror the skull first"};
  if (step == kSmoothStep && !(s.implant && s.implant->result().usable()))
    throw Refusal{"step 8 cannot be done: build the implant first"};
  if (!by_hand && !step_complete(s, step, &missing))
    throw Refusal{"step " + std::to_string(step) + " is not done: " + missing};
  if (by_hand) s.acknowledged[step] = true;
  s.stale.erase(step);
  s.current_step = std::min(kStepCount, step + 1);
  s.message = std::string("step ") + std::to_string(step) + " done";
}

}  // namespace

Json proposal_result(const MarkerProposal& p) {
  if (!p.proposed())
    return Json{{"proposed", false},          {"markers", Json::array()},
                {"defect_center", nullptr},   {"unseen_rim", Json::array()},
                {"scan_ends", Json::array()}, {"message", "no markers proposed: " + p.message}};
  const std::string proposed = std::to_string(p.markers.size()) + " markers proposed, " +
                               describe_method(p.method_used, p.mirror_coverage) + "; ";
  Json unseen = Json::array();
  for (const RimStretch& g : p.defect.unseen_rim)
    unseen.push_back(Json{{"from", to_json(g.from)}, {"to", to_json(g.to)}});
  return Json{{"proposed", true},
              {"markers", markers_to_json(p.markers)["markers"]},
              {"defect_center", to_json(p.defect.center)},
              {"unseen_rim", unseen},
              {"scan_ends", to_json(p.defect.scan_ends)},
              {"message", proposed + p.message + "; " + p.surfaces_message}};
}

ApplyOutcome apply_command(const PlanState& before, const Command& command,
                           const ApplyContext& context) {
  ApplyOutcome out;
  const int step = command_step(before, command);
  std::string why;
  if (step >= kLoadStep && !step_unlocked(before, step, &why)) {
    out.message = why;
    out.state = before;
    return out;
  }
  PlanState s = before;
  s.message.clear();
  const std::string where = std::string("command ") + type_tag(command.type);
  const ParamReader r(command.params, where);
  try {
    switch (command.type) {
      case CommandType::LoadSkull:
        apply_load(s, r, context, out.record);
        break;
      case CommandType::SetLandmark:
        apply_landmark(s, r, true);
        break;
      case CommandType::ClearLandmark:
        apply_landmark(s, r, false);
        break;
      case CommandType::FitPlane:
        apply_fit_plane(s, r, command.version, out.record);
        break;
      case CommandType::AdjustPlane:
        apply_adjust_plane(s, r, command.version, out.record);
        break;
      case CommandType::Mirror:
        apply_mirror(s);
        break;
      case CommandType::Register:
        apply_register(s, r, command.version, out.record);
        break;
      case CommandType::MoveMirrored:
        apply_move_mirrored(s, r);
        break;
      case CommandType::SetClipPlane:
        apply_clip(s, r);
        break;
      case CommandType::AddMarker:
      case CommandType::MoveMarker:
      case CommandType::DeleteMarker:
      case CommandType::RetypeMarker:
      case CommandType::ImportMarkers:
      case CommandType::ClearMarkers:
        apply_marker_edit(s, command.type, r);
        break;
      case CommandType::ProposeMarkers:
        apply_propose(s, r, command.version, context, out.record);
        break;
      case CommandType::SmoothMarkers:
        apply_smooth(s, r);
        break;
      case CommandType::BuildImplant:
        apply_build(s, r, command.version);
        break;
      case CommandType::ExportImplant:
        apply_export(s, r, command.version);
        break;
      case CommandType::GoToStep:
      case CommandType::CompleteStep:
        apply_step(s, command.type, r);
        break;
      case CommandType::Note:
        s.notes.push_back(r.string("text"));
        s.message = "note added";
        break;
      case CommandType::AttachCt:
        apply_attach_ct(s, r, context, out.record);
        break;
      case CommandType::Approve:
        apply_approve(s, r);
        break;
    }
  } catch (const Refusal& refusal) {
    out.message = refusal.message;
    out.state = before;
    return out;
  }
  // A sign-off holds for the implant signed, not for another.
  if (s.approval && (!s.implant || s.implant->stl_sha256() != s.approval->implant_sha256)) {
    s.approval_withdrawn = "the implant changed after " + s.approval->by + " approved it";
    s.approval.reset();
    s.message += (s.message.empty() ? "" : "; ") + s.approval_withdrawn + ": approval withdrawn";
  }
  if (step >= kLoadStep) s.stale.erase(step);
  out.accepted = true;
  out.message = s.message;
  out.state = std::move(s);
  return out;
}

}  // namespace cranioplan
