#include "cli_implant_commands.h"

#include <Eigen/LU>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>

#include "cli_output.h"
#include "cli_session_commands.h"
#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/geometry/voxelize_mesh.h"
#include "cranioplan/algorithms/implant/build_implant.h"
#include "cranioplan/algorithms/implant/smooth_markers.h"
#include "cranioplan/algorithms/implant/snap_markers.h"
#include "cranioplan/algorithms/io/load_skull.h"
#include "cranioplan/algorithms/io/read_volume.h"
#include "cranioplan/algorithms/io/write_labelmap.h"
#include "cranioplan/algorithms/io/write_mesh.h"
#include "cranioplan/algorithms/planning/autoplan.h"
#include "cranioplan/algorithms/planning/detect_defect.h"
#include "cranioplan/algorithms/quality/check_implant.h"
#include "cranioplan/algorithms/quality/compare_implants.h"
#include "cranioplan/algorithms/quality/inject_defect.h"
#include "cranioplan/algorithms/quality/soft_tissue_check.h"
#include "cranioplan/model/error.h"
#include "cranioplan/sessions/autoplan_session.h"
#include "cranioplan/sessions/marker_files.h"

namespace cranioplan::cli {
namespace {

// Skulls are used where load_skull put them (`const LoadedSkull loaded = ...; loaded.mesh`), never
// copied out: OpenMesh meshes have no move constructor, and a copy of a SkullFix skull is 300 MB.

// Meshes, or label volumes (e.g. SkullFix NRRD masks) turned into surfaces with every piece kept.
SkullMesh load_any(const std::string& path) {
  ExtractBoneSurfaceParams p;
  p.largest_piece_only = false;
  p.min_piece_triangles = 1;
  return load_surface(path, p).mesh;
}

Json implant_json(const ImplantResult& r) {
  static const char* names[] = {"built", "too_few_markers", "failed"};
  return Json{{"status", names[static_cast<int>(r.status)]},
              {"message", r.message},
              {"watertight", r.watertight},
              {"triangles", r.mesh.n_faces()},
              {"thickness_used_mm", r.thickness_used_mm},
              {"rim_marker_error_mm", r.rim_marker_error_mm},
              {"rim_points", r.rim_points},
              {"seconds", r.seconds}};
}

std::vector<double> unseen_rim_lengths(const std::vector<RimStretch>& stretches) {
  std::vector<double> mm;
  for (const RimStretch& s : stretches) mm.push_back(s.length_mm());
  return mm;
}

Json autoplan_json(const AutoplanResult& r) {
  Json j{{"status", r.planned()                                    ? "planned"
                    : r.status == AutoplanResult::Status::NoDefect ? "no_defect"
                                                                   : "failed"},
         {"message", r.message},
         {"plane", to_json(r.plane.plane)},
         {"transform", to_json(r.registration.transform)},
         {"registration_rms_mm", r.registration.rms_mm}};
  if (r.defect.found()) {
    j["defect"] = Json{{"area_mm2", r.defect.area_mm2},
                       {"axis", to_json(r.defect.axis)},
                       {"rim_points", r.defect.outer_rim.size()},
                       {"unseen_rim_mm", unseen_rim_lengths(r.defect.unseen_rim)},
                       {"other_openings", r.defect.other_openings}};
    Json others = Json::array();
    for (const auto& a : r.defect.other_axes) others.push_back(to_json(a));
    j["defect"]["other_axes"] = others;
    j["method"] = to_string(r.method_used);
    j["mirror_coverage"] = r.mirror_coverage;
    j["markers"] = r.markers.size();
  }
  if (r.planned()) {
    j["implant"] = implant_json(r.implant);
    j["quality"] = to_json(r.quality);
  }
  Json times = Json::object();
  double total = 0.0;
  for (const auto& [name, sec] : r.stage_seconds) {
    times[name] = sec;
    total += sec;
  }
  times["total"] = total;
  j["seconds"] = times;
  return j;
}

// --fit-to-bone MM: the automatic planner's implant built beyond the rim and trimmed by the bone.
void add_fit_option(CLI::App* cmd, AutoplanParams& params) {
  cmd->add_option("--fit-to-bone", params.implant.fit_to_bone_mm,
                  "build the implant this far over the bone and subtract the skull (mm; 0: off)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 10.0));
  cmd->add_option("--local-registration", params.local_registration_mm,
                  "register the mirror again within this margin of the opening (mm; 0: off)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 200.0));
}

// The k-th of several outputs: the path itself for the first, else "name_k.ext" beside it.
std::string numbered_path(const std::string& path, size_t k) {
  if (k <= 1) return path;
  const std::filesystem::path p(path);
  return (p.parent_path() / (p.stem().string() + "_" + std::to_string(k) + p.extension().string()))
      .string();
}

// The reports of several plans, one per opening: {"openings", "plans"} as JSON, else each in
// turn.
void print_plans(const Json& plans, bool json) {
  if (json) {
    print_result(Json{{"openings", plans.size()}, {"plans", plans}}, true);
    return;
  }
  for (size_t k = 0; k < plans.size(); ++k) {
    std::cout << "opening " << k + 1 << " of " << plans.size() << ":\n";
    print_result(plans[k], false);
  }
}

// autoplan --session: one automatic plan made by session commands and saved for reopening and
// audit; its report. `a` keeps the status and the opening found, not the session.
Json autoplan_with_session(const std::string& skull, const ExtractBoneSurfaceParams& import,
                           const Landmarks& lm, const AutoplanParams& params,
                           const std::string& output, const std::string& markers_out,
                           const std::string& session_path, bool all_openings, AutoplanSession& a) {
  a = autoplan_session(skull, lm, params, output, {}, import, all_openings);
  a.session.save(session_path);
  const PlanState& s = a.session.state();
  Json j{{"status", a.planned()                                     ? "planned"
                    : a.status == AutoplanSession::Status::NoDefect ? "no_defect"
                                                                    : "failed"},
         {"message", a.message}};
  j.update(plan_state_json(s));
  if (s.skull && !s.skull->surface->loaded.warnings.empty())
    j["warnings"] = s.skull->surface->loaded.warnings;
  Json times = Json::object();
  for (const auto& c : a.session.effective_commands())
    times[type_tag(c.type)] = c.meta.duration_ms / 1000.0;
  j["seconds"] = times;
  j["session"] = session_path;
  if (!markers_out.empty() && !s.markers.empty()) write_markers_file(s.markers, markers_out);
  if (a.planned()) j["output"] = output;
  a.session = Session();  // saved; its meshes freed before the next opening is planned
  return j;
}

// autoplan --session [--all-openings]: a session per opening, each holding its own commands
// (the plane and the registration included), so that each can be reopened and replayed alone.
int autoplan_sessions(const std::string& skull, const ExtractBoneSurfaceParams& import,
                      const Landmarks& lm, const AutoplanParams& params, const std::string& output,
                      const std::string& markers_out, const std::string& session, bool all_openings,
                      bool json) {
  AutoplanSession first;
  Json j = autoplan_with_session(skull, import, lm, params, output, markers_out, session,
                                 all_openings, first);
  if (!all_openings || !first.defect.found()) {
    print_result(j, json);
    return first.planned() ? kOk : kUnusable;
  }
  Json plans = Json::array({j});
  bool all_planned = first.planned();
  for (size_t k = 0; k < first.defect.other_axes.size(); ++k) {
    AutoplanParams each = params;
    each.propose.detect.near = point_towards_other_opening(first.defect, k);
    AutoplanSession a;
    Json one = autoplan_with_session(skull, import, lm, each, numbered_path(output, k + 2),
                                     markers_out.empty() ? "" : numbered_path(markers_out, k + 2),
                                     numbered_path(session, k + 2), true, a);
    plans.push_back(one);
    all_planned = all_planned && a.planned();
  }
  print_plans(plans, json);
  return all_planned ? kOk : kUnusable;
}

// Writes one automatic plan's markers (if asked for) and implant (if planned); its report.
Json write_autoplan(const AutoplanResult& r, const std::string& output,
                    const std::string& markers_out) {
  Json j = autoplan_json(r);
  if (!markers_out.empty() && !r.markers.empty()) write_markers_file(r.markers, markers_out);
  if (r.planned()) {
    write_mesh(r.implant.mesh, output);
    j["output"] = output;
  }
  return j;
}

// A scored plan's row (evaluate, study): the method it used and its agreement with the truth.
void add_scores(Json& row, const AutoplanResult& r, const CompareResult& c) {
  row["method"] = to_string(r.method_used);
  row["dice"] = c.dice;
  row["boundary_dice"] = c.boundary_dice;
  row["hd95_mm"] = c.hd95_mm;
  // Whether the plan could go to the printer as it stands (the quality report's verdict).
  row["printable"] = r.quality.printable;
  row["rim_gap_mm"] = r.quality.rim_gap_mm;
  if (!r.quality.printable) row["not_printable_because"] = r.quality.reasons;
}

// The printable verdict of a scored row, for the text table.
std::string printable_text(const Json& row) {
  if (!row.contains("printable")) return "";
  if (row["printable"].get<bool>()) return "printable  ";
  const Json& why = row["not_printable_because"];
  return "NOT printable (" + (why.empty() ? std::string("?") : why[0].get<std::string>()) + ")  ";
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

// smooth
Subcommand add_smooth(CLI::App& app, const bool& json) {
  struct Opts {
    std::string markers, output, mirrored;
    SmoothParams params;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("smooth", "The paper's Laplacian smoother on surface markers");
  cmd->add_option("MARKERS", o->markers, "markers (.json, .csv or Slicer .mrk.json)")->required();
  cmd->add_option("--radius", o->params.radius_mm, "neighbourhood radius (mm)")
      ->required()
      ->check(CLI::PositiveNumber);
  cmd->add_option("--edge-weight", o->params.edge_weight, "weight of edge markers (>= 1)")
      ->required()
      ->check(CLI::Range(1.0, 1e6));
  cmd->add_option("--iterations", o->params.iterations, "iterations (default 1)")
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--project-onto", o->mirrored,
                  "put smoothed surface markers back onto this mesh (the mirrored skull)");
  cmd->add_option("-o,--output", o->output, "markers to write (.json, .csv or Slicer .mrk.json)")
      ->required();
  return Subcommand{cmd, [o, &json] {
                      const auto markers = read_markers_file(o->markers);
                      std::unique_ptr<SurfaceLocator> surface;
                      SkullMesh mirrored;
                      if (!o->mirrored.empty()) {
                        mirrored = load_skull(o->mirrored).mesh;
                        surface = std::make_unique<SurfaceLocator>(mirrored);
                      }
                      const SmoothResult r = smooth_markers(markers, o->params, surface.get());
                      const bool ok = r.status == SmoothResult::Status::Smoothed;
                      if (ok) write_markers_file(r.markers, o->output);
                      print_result(Json{{"status", ok ? "smoothed" : "too_few_markers"},
                                        {"message", r.message},
                                        {"markers", r.markers.size()},
                                        {"max_move_mm", r.max_move_mm}},
                                   json);
                      return ok ? kOk : kUnusable;
                    }};
}

// implant
Subcommand add_implant(CLI::App& app, const bool& json) {
  struct Opts {
    std::string skull, mirrored, markers, output, method = "shell";
    ImplantParams params;
    bool no_snap = false;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("implant", "Build an implant from markers");
  cmd->add_option("--skull", o->skull, "the original (defective) skull")->required();
  cmd->add_option("--mirrored", o->mirrored,
                  "the registered mirrored skull (surface markers are snapped onto it)");
  cmd->add_option("--markers", o->markers, "markers (.json, .csv or Slicer .mrk.json)")->required();
  cmd->add_option("--method", o->method, "shell (default) or delaunay3d")
      ->check(CLI::IsMember({"shell", "delaunay3d"}));
  cmd->add_option("--resolution", o->params.resolution_mm, "shell edge length (mm)")
      ->check(CLI::Range(0.2, 10.0));
  cmd->add_option("--thickness", o->params.thickness_mm,
                  "thickness without inner markers (mm; default: bone around the rim)")
      ->check(CLI::Range(0.5, 30.0));
  cmd->add_flag("--no-rim-snap", o->no_snap,
                "keep the rim between markers where the spline puts it");
  cmd->add_option("--alpha", o->params.delaunay_alpha, "delaunay3d alpha (mm; 0 = convex hull)");
  cmd->add_option("--tolerance", o->params.delaunay_tolerance, "delaunay3d tolerance");
  cmd->add_option("--offset", o->params.delaunay_offset, "delaunay3d offset");
  cmd->add_option("-o,--output", o->output, "implant to write (.stl or .ply)")->required();
  return Subcommand{
      cmd, [o, &json] {
        const std::vector<Marker> raw = read_markers_file(o->markers);
        const LoadedSkull loaded = load_skull(o->skull);
        const SkullMesh& skull = loaded.mesh;
        const SurfaceLocator skull_surface(skull);
        SkullMesh mirrored;
        std::unique_ptr<SurfaceLocator> mirrored_surface;
        if (!o->mirrored.empty()) {
          mirrored = load_skull(o->mirrored).mesh;
          mirrored_surface = std::make_unique<SurfaceLocator>(mirrored);
        }
        const SnapMarkersResult snapped = snap_markers(raw, skull_surface, mirrored_surface.get());
        if (snapped.status != SnapMarkersResult::Status::Snapped)
          throw InputError(o->markers, snapped.message);
        o->params.method = o->method == "shell" ? ImplantMethod::Shell : ImplantMethod::Delaunay3D;
        o->params.snap_rim_to_skull = !o->no_snap;
        const ImplantResult r = build_implant(snapped.markers, &skull, o->params);
        Json j = implant_json(r);
        j["method"] = o->method;
        j["marker_snap_max_mm"] = snapped.max_distance_mm;
        if (!r.usable()) {
          print_result(j, json);
          return kUnusable;
        }
        write_mesh(r.mesh, o->output);
        j["output"] = o->output;
        j["quality"] = to_json(check_implant(r.mesh, &skull));
        print_result(j, json);
        return kOk;
      }};
}

// qa
Subcommand add_qa(CLI::App& app, const bool& json) {
  struct Opts {
    std::string implant, skull, ct, series;
    QualityParams params;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("qa", "Quality report of an implant before printing");
  cmd->add_option("IMPLANT", o->implant, "implant mesh")->required();
  cmd->add_option("--skull", o->skull, "the (defective) skull it is made for");
  cmd->add_option("--ct", o->ct,
                  "the patient's CT: also the soft tissue under the implant (brain, dura)");
  add_series_option(cmd, o->series);
  cmd->add_option("--min-thickness", o->params.min_thickness_mm, "thinnest printable (mm)");
  cmd->add_option("--max-taper", o->params.max_taper_mm,
                  "widest edge on the bone that may be thinner (mm)");
  cmd->add_option("--max-rim-gap", o->params.max_rim_gap_mm, "largest acceptable rim gap (mm)");
  cmd->add_option("--max-penetration", o->params.max_penetration_mm3,
                  "largest acceptable overlap (mm³)");
  return Subcommand{cmd, [o, &json] {
                      const SkullMesh implant = load_surface(o->implant).mesh;
                      SkullMesh skull;
                      if (!o->skull.empty()) skull = load_skull(o->skull).mesh;
                      const QualityReport q =
                          check_implant(implant, o->skull.empty() ? nullptr : &skull, o->params);
                      Json j = to_json(q);
                      if (!o->ct.empty()) {
                        ReadVolumeParams read;
                        read.dicom_series = o->series;
                        const Volume ct = read_volume(o->ct, read);
                        // The cavity's side: the skull's centre, else the CT's.
                        Eigen::Vector3d inside = ct.world(
                            0.5 * Eigen::Vector3d(ct.dims[0] - 1, ct.dims[1] - 1, ct.dims[2] - 1));
                        if (!o->skull.empty()) {
                          const auto [lo, hi] = mesh_bounds(skull);
                          inside = 0.5 * (lo + hi);
                        }
                        j["soft_tissue"] = to_json(check_soft_tissue(implant, ct, inside));
                      }
                      print_result(j, json);
                      return q.printable ? kOk : kUnusable;
                    }};
}

// labelmap
Subcommand add_labelmap(CLI::App& app, const bool& json) {
  struct Opts {
    std::string implant, reference, output, series;
    LabelSegment segment;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand(
      "labelmap", "The implant as a labelmap on a CT's grid (.nrrd, or a Slicer .seg.nrrd)");
  cmd->add_option("IMPLANT", o->implant, "implant mesh")->required();
  cmd->add_option("--reference", o->reference, "the CT whose grid to use (any volume format)")
      ->required();
  cmd->add_option("-o,--output", o->output, "labelmap to write (.nrrd or .seg.nrrd)")->required();
  cmd->add_option("--name", o->segment.name, "the segment's name in a .seg.nrrd");
  add_series_option(cmd, o->series);
  return Subcommand{cmd, [o, &json] {
                      const SkullMesh implant = load_surface(o->implant).mesh;
                      ReadVolumeParams read;
                      read.dicom_series = o->series;
                      const Volume grid = read_volume(o->reference, read);
                      const std::vector<uint8_t> labels = labelmap_on_grid(implant, grid);
                      write_labelmap_nrrd(labels, grid, o->output, o->segment);
                      long long inside = 0;
                      for (uint8_t l : labels) inside += l;
                      const double voxel = std::abs(grid.directions.determinant());
                      Json j{{"output", o->output},
                             {"grid", {grid.dims[0], grid.dims[1], grid.dims[2]}},
                             {"voxels", inside},
                             {"volume_mm3", inside * voxel},
                             {"mesh_volume_mm3", signed_volume(implant)}};
                      print_result(j, json);
                      return inside > 0 ? kOk : kUnusable;
                    }};
}

// compare
Subcommand add_compare(CLI::App& app, const bool& json) {
  struct Opts {
    std::string a, b, skull;
    CompareParams params;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("compare", "Dice, boundary Dice, HD, HD95 between two implants");
  cmd->add_option("IMPLANT", o->a, "implant (mesh or NRRD/NIfTI mask)")->required();
  cmd->add_option("REFERENCE", o->b, "reference implant (mesh or mask)")->required();
  cmd->add_option("--defective-skull", o->skull,
                  "defective skull for boundary Dice (mesh or mask)");
  cmd->add_option("--spacing", o->params.spacing_mm, "voxel size of the common grid (mm)")
      ->check(CLI::Range(0.1, 2.0));
  return Subcommand{cmd, [o, &json] {
                      const SkullMesh a = load_any(o->a), b = load_any(o->b);
                      SkullMesh skull;
                      if (!o->skull.empty()) skull = load_any(o->skull);
                      const CompareResult r =
                          compare_implants(a, b, o->skull.empty() ? nullptr : &skull, o->params);
                      print_result(to_json(r), json);
                      return kOk;
                    }};
}

// inject-defect
Subcommand add_inject_defect(CLI::App& app, const bool& json) {
  struct Opts {
    std::string skull, center, shape = "sphere", output, implant;
    InjectDefectParams params;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("inject-defect",
                                 "Cut a defect out of a healthy skull, keeping the ground truth");
  cmd->add_option("SKULL", o->skull, "healthy skull (closed mesh or volume)")->required();
  cmd->add_option("--center", o->center, "defect centre x,y,z (mm)")->required();
  cmd->add_option("--size", o->params.size_mm, "sphere diameter or cube edge (mm)")
      ->required()
      ->check(CLI::PositiveNumber);
  cmd->add_option("--shape", o->shape, "sphere or cube")->check(CLI::IsMember({"sphere", "cube"}));
  cmd->add_option("--voxel", o->params.voxel_mm, "resolution of the cut (mm)")
      ->check(CLI::Range(0.1, 2.0));
  cmd->add_option("-o,--output", o->output, "defective skull to write")->required();
  cmd->add_option("--implant", o->implant, "ground-truth implant to write")->required();
  return Subcommand{cmd, [o, &json] {
                      o->params.center = parse_point(o->center, "--center");
                      o->params.shape = o->shape == "cube" ? InjectDefectParams::Shape::Cube
                                                           : InjectDefectParams::Shape::Sphere;
                      const LoadedSkull loaded = load_skull(o->skull);
                      const SkullMesh& skull = loaded.mesh;
                      const InjectDefectResult r = inject_defect(skull, o->params);
                      Json j{{"status", r.usable() ? "injected" : "no_bone_in_defect"},
                             {"message", r.message},
                             {"removed_volume_mm3", r.removed_volume_mm3},
                             {"seconds", r.seconds}};
                      if (!r.usable()) {
                        print_result(j, json);
                        return kUnusable;
                      }
                      write_mesh(r.defective, o->output);
                      write_mesh(r.implant, o->implant);
                      j["defective"] = o->output;
                      j["implant"] = o->implant;
                      print_result(j, json);
                      return kOk;
                    }};
}

// autoplan
Subcommand add_autoplan(CLI::App& app, const bool& json) {
  struct Opts {
    std::string skull, landmarks, output, markers_out, session, method = "auto";
    std::vector<double> near;
    bool all_openings = false;
    AutoplanParams params;
    ExtractBoneSurfaceParams import;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd =
      app.add_subcommand("autoplan", "Plan an implant automatically from a defective skull");
  cmd->add_option("SKULL", o->skull, "defective skull (mesh or volume)")->required();
  cmd->add_option("--landmarks", o->landmarks,
                  "landmarks for the midsagittal plane (.json or Slicer .mrk.json)");
  cmd->add_option("--method", o->method, "auto, mirror or rim-only")
      ->check(CLI::IsMember({"auto", "mirror", "rim-only"}));
  cmd->add_option("-o,--output", o->output, "implant to write (.stl or .ply)")->required();
  cmd->add_option("--markers-out", o->markers_out,
                  "proposed markers to write (.json, .csv or Slicer .mrk.json)");
  add_units_option(cmd, o->import.mesh_unit_mm);
  add_series_option(cmd, o->import.dicom_series);
  cmd->add_option("--near", o->near,
                  "X Y Z (mm): with several openings, plan the one in this point's direction "
                  "(default: the largest)")
      ->expected(3);
  add_fit_option(cmd, o->params);
  cmd->add_option("--session", o->session,
                  "plan through session commands and save the session (.json): reopen, edit, "
                  "replay and audit it (with --all-openings, SESSION_2... for the others)");
  cmd->add_flag("--all-openings", o->all_openings,
                "plan every opening large enough to be a defect (bilateral defects), each to "
                "its own implant: IMPLANT, then IMPLANT_2, IMPLANT_3... (markers and sessions "
                "likewise)");
  return Subcommand{
      cmd, [o, &json]() -> int {
        if (o->near.size() == 3)
          o->params.propose.detect.near = Eigen::Vector3d(o->near[0], o->near[1], o->near[2]);
        const Landmarks lm = o->landmarks.empty() ? Landmarks{} : read_landmarks_file(o->landmarks);
        plan_method_from_string(o->method, o->params.propose.method);
        auto markers_path = [&](size_t k) {
          return o->markers_out.empty() ? std::string() : numbered_path(o->markers_out, k);
        };
        if (!o->session.empty())
          return autoplan_sessions(o->skull, o->import, lm, o->params, o->output, o->markers_out,
                                   o->session, o->all_openings, json);
        const LoadedSkull loaded = load_skull(o->skull, o->import);
        const SkullMesh& skull = loaded.mesh;
        // The reader's warnings (a skull turned outward, non-manifold edges) with the plan.
        auto with_warnings = [&loaded](Json j) {
          if (!loaded.warnings.empty()) j["warnings"] = loaded.warnings;
          return j;
        };
        if (!o->all_openings) {
          const AutoplanResult r = autoplan(skull, lm, o->params);
          print_result(with_warnings(write_autoplan(r, o->output, o->markers_out)), json);
          return r.planned() ? kOk : kUnusable;
        }
        // Every opening in turn; the first is the one planned without
        // --all-openings.
        const std::vector<AutoplanResult> all = autoplan_all_openings(skull, lm, o->params);
        if (!all.front().defect.found()) {  // no defect, or no plane
          print_result(with_warnings(write_autoplan(all.front(), o->output, o->markers_out)), json);
          return all.front().planned() ? kOk : kUnusable;
        }
        Json plans = Json::array();
        bool all_planned = true;
        for (size_t k = 0; k < all.size(); ++k) {
          plans.push_back(with_warnings(
              write_autoplan(all[k], numbered_path(o->output, k + 1), markers_path(k + 1))));
          all_planned = all_planned && all[k].planned();
        }
        print_plans(plans, json);
        return all_planned ? kOk : kUnusable;
      }};
}

// evaluate
Subcommand add_evaluate(CLI::App& app, const bool& json) {
  struct Opts {
    std::string dir, implants_out;
    AutoplanParams params;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand(
      "evaluate",
      "Autoplan every NNN_defective_skull.* against its NNN_implant.* (exit 1 if a case could "
      "not be planned, 3 if a case's file could not be read; every case is in the table)");
  cmd->add_option("CASES_DIR", o->dir, "folder of cases (meshes or NRRD/NIfTI masks)")->required();
  cmd->add_option("--implants-out", o->implants_out,
                  "folder to write each planned implant to (NNN_planned_implant.stl)");
  add_fit_option(cmd, o->params);
  return Subcommand{
      cmd, [o, &json] {
        namespace fs = std::filesystem;
        if (!fs::is_directory(o->dir)) throw InputError(o->dir, "is not a folder");
        if (!o->implants_out.empty() && !fs::is_directory(o->implants_out))
          throw InputError(o->implants_out, "is not a folder (--implants-out)");
        std::map<std::string, std::pair<std::string, std::string>>
            cases;  // id → (defective, implant)
        for (const auto& e : fs::directory_iterator(o->dir)) {
          const std::string name = e.path().filename().string();
          const size_t us = name.find('_');
          if (us == std::string::npos) continue;
          const std::string id = name.substr(0, us), rest = name.substr(us + 1);
          if (rest.rfind("defective_skull.", 0) == 0) cases[id].first = e.path().string();
          if (rest.rfind("implant.", 0) == 0) cases[id].second = e.path().string();
        }
        Json rows = Json::array();
        std::vector<double> dsc, bdsc, hd95, secs;
        int failed = 0, unreadable = 0, printable = 0;
        for (const auto& [id, files] : cases) {
          if (files.first.empty() || files.second.empty()) continue;
          double seconds = 0.0;
          bool read = true;
          Json row{{"case", id}};
          // One case's unreadable file is that case's row, not the end of the run: the
          // others are still planned and scored.
          try {
            // The truth is read first (to fail before planning) and not timed: the time is
            // the plan's, from reading the skull to the implant.
            const SkullMesh truth = load_any(files.second);
            const auto t0 = std::chrono::steady_clock::now();
            const LoadedSkull loaded = load_skull(files.first);
            const SkullMesh& skull = loaded.mesh;
            const AutoplanResult r = autoplan(skull, Landmarks{}, o->params);
            seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            row["status"] = r.planned() ? "planned" : "failed";
            row["message"] = r.message;
            if (r.planned()) {
              const CompareResult c = compare_implants(r.implant.mesh, truth, &skull);
              if (!o->implants_out.empty()) {
                const std::string path =
                    (fs::path(o->implants_out) / (id + "_planned_implant.stl")).string();
                write_mesh(r.implant.mesh, path);
                row["implant"] = path;
              }
              add_scores(row, r, c);
              printable += r.quality.printable;
              dsc.push_back(c.dice);
              bdsc.push_back(c.boundary_dice);
              hd95.push_back(c.hd95_mm);
            } else {
              // No implant overlaps nothing: a failed plan counts as Dice 0 in the medians
              // (as a missing prediction does in the challenge); it has no distance.
              ++failed;
              dsc.push_back(0.0);
              bdsc.push_back(0.0);
            }
          } catch (const Error& e) {
            ++unreadable;
            read = false;
            row["status"] = "bad_input";
            row["message"] = e.what();
          }
          row["seconds"] = read ? Json(seconds) : Json(nullptr);  // no plan, no time
          if (read) secs.push_back(seconds);
          if (!json) {
            if (row["status"] == "planned")
              std::cout << id << "  " << row["method"].get<std::string>() << "  DSC "
                        << row["dice"].get<double>() << "  bDSC "
                        << row["boundary_dice"].get<double>() << "  HD95 "
                        << row["hd95_mm"].get<double>() << " mm  " << seconds << " s  "
                        << printable_text(row) << row["message"].get<std::string>() << std::endl;
            else
              std::cout << id << "  " << row["status"].get<std::string>() << "  "
                        << row["message"].get<std::string>() << std::endl;
          }
          rows.push_back(row);
        }
        if (rows.empty())
          throw InputError(o->dir,
                           "holds no NNN_defective_skull.* with an NNN_implant.* beside it");
        // No figure where no case gave one (null, not 0).
        auto median_of = [](const std::vector<double>& v) {
          return v.empty() ? Json(nullptr) : Json(median(v));
        };
        const Json summary{{"cases", rows.size()},
                           {"printable", printable},
                           {"failed", failed},
                           {"bad_input", unreadable},
                           {"median_dice", median_of(dsc)},
                           {"median_boundary_dice", median_of(bdsc)},
                           {"median_hd95_mm", median_of(hd95)},
                           {"median_seconds", median_of(secs)}};
        if (json)
          print_result(Json{{"cases", rows}, {"median", summary}}, true);
        else
          print_result(Json{{"median", summary}}, false);
        // Every case is in the table; the exit code says whether all of them were planned.
        if (unreadable > 0) return kBadInput;
        if (failed > 0) return kUnusable;
        return kOk;
      }};
}

// study: inject one-sided defects into a healthy skull, plan them, score them
Subcommand add_study(CLI::App& app, const bool& json) {
  struct Opts {
    std::string skull;
    int count = 10;
    double min_size = 30.0, max_size = 50.0;
    AutoplanParams params;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand(
      "study", "Inject one-sided defects into a healthy skull, autoplan and score each");
  cmd->add_option("SKULL", o->skull, "healthy skull (mesh or volume)")->required();
  cmd->add_option("--count", o->count, "number of defects (default 10)")->check(CLI::Range(1, 100));
  cmd->add_option("--min-size", o->min_size, "smallest sphere diameter (mm)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--max-size", o->max_size, "largest sphere diameter (mm)")
      ->check(CLI::PositiveNumber);
  add_fit_option(cmd, o->params);
  return Subcommand{
      cmd, [o, &json] {
        const LoadedSkull loaded = load_skull(o->skull);
        const SkullMesh& skull = loaded.mesh;
        const SurfaceLocator bone(skull);
        // Directions on the upper vault, alternately left and right, spread by the golden angle;
        // each defect's centre is in the middle of the bone along that ray from the centroid.
        Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
        for (auto vh : skull.vertices()) centroid += to_eigen(skull.point(vh));
        centroid /= static_cast<double>(skull.n_vertices());
        Json rows = Json::array();
        std::vector<double> dsc, hd95;
        int printable = 0;
        for (int k = 0; k < o->count; ++k) {
          const double side = k % 2 == 0 ? 1.0 : -1.0;
          const double phi = 2.39996 * k, up = 0.25 + 0.5 * std::fmod(0.618034 * k, 1.0);
          const Eigen::Vector3d dir =
              Eigen::Vector3d(side * (0.55 + 0.25 * std::abs(std::cos(phi))), 0.6 * std::sin(phi),
                              up)
                  .normalized();
          const auto out_hit = bone.first_hit(centroid + 400.0 * dir, centroid);
          const auto in_hit = bone.first_hit(centroid, centroid + 400.0 * dir);
          if (!out_hit || !in_hit) continue;
          InjectDefectParams ip;
          ip.center = 0.5 * (out_hit->point + in_hit->point);
          ip.size_mm =
              o->min_size + (o->max_size - o->min_size) * std::fmod(0.381966 * (k + 1), 1.0);
          ip.voxel_mm = 0.5;
          const InjectDefectResult d = inject_defect(skull, ip);
          if (!d.usable()) continue;
          // The skull may have a defect of its own (the sample has): the planner is told
          // which opening is meant, as a user would point at it.
          AutoplanParams params = o->params;
          params.propose.detect.near = ip.center;
          const AutoplanResult r = autoplan(d.defective, Landmarks{}, params);
          Json row{{"center", to_json(ip.center)}, {"size_mm", ip.size_mm}, {"message", r.message}};
          if (r.planned()) {
            const CompareResult c = compare_implants(r.implant.mesh, d.implant, &d.defective);
            add_scores(row, r, c);
            printable += r.quality.printable;
            dsc.push_back(c.dice);
            hd95.push_back(c.hd95_mm);
          } else {
            dsc.push_back(0.0);
          }
          if (!json)
            std::cout << k << "  size " << ip.size_mm << " mm  " << row.value("method", "-")
                      << "  DSC " << row.value("dice", 0.0) << "  HD95 "
                      << row.value("hd95_mm", 0.0) << " mm  " << printable_text(row) << r.message
                      << std::endl;
          rows.push_back(row);
        }
        const Json summary{{"defects", rows.size()},
                           {"printable", printable},
                           {"median_dice", median(dsc)},
                           {"median_hd95_mm", median(hd95)}};
        if (json)
          print_result(Json{{"defects", rows}, {"median", summary}}, true);
        else
          print_result(Json{{"median", summary}}, false);
        return kOk;
      }};
}

}  // namespace

std::vector<Subcommand> add_implant_commands(CLI::App& app, const bool& json) {
  return {add_smooth(app, json),   add_implant(app, json),  add_qa(app, json),
          add_labelmap(app, json), add_compare(app, json),  add_inject_defect(app, json),
          add_autoplan(app, json), add_evaluate(app, json), add_study(app, json)};
}

}  // namespace cranioplan::cli
