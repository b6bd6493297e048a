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
#include "cli_planning.h"
#include "cli_session_commands.h"
#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/geometry/voxelize_mesh.h"
#include "cranioplan/algorithms/implant/build_implant.h"
#include "cranioplan/algorithms/implant/casting_mould.h"
#include "cranioplan/algorithms/implant/smooth_markers.h"
#include "cranioplan/algorithms/implant/snap_markers.h"
#include "cranioplan/algorithms/io/file_io.h"
#include "cranioplan/algorithms/io/load_skull.h"
#include "cranioplan/algorithms/io/read_volume.h"
#include "cranioplan/algorithms/io/write_3mf.h"
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
// copied out: OpenMesh meshes have no move constructor, and every copy of a skull costs its whole
// size again (docs/BENCHMARKS.md, "Where the memory goes, and what bounds it").

Json implant_json(const ImplantResult& r) {
  Json holes = Json::array();
  for (const Hole& h : r.holes)
    holes.push_back(Json{{"center", to_json(h.center)}, {"axis", to_json(h.axis)}});
  Json tabs = Json::array();
  for (const Tab& t : r.tabs) {
    Json screws = Json::array();
    for (const Hole& h : t.screws)
      screws.push_back(Json{{"center", to_json(h.center)}, {"axis", to_json(h.axis)}});
    tabs.push_back(Json{{"rim", to_json(t.rim)},
                        {"outward", to_json(t.outward)},
                        {"normal", to_json(t.normal)},
                        {"screws", screws},
                        {"bone_mm", t.bone_mm},
                        {"midline_mm", std::isnan(t.midline_mm) ? Json() : Json(t.midline_mm)}});
  }
  return Json{{"status", status_name(r.status)},
              {"holes", holes},
              {"tabs", tabs},
              {"message", r.message},
              {"watertight", r.watertight},
              {"triangles", r.mesh.n_faces()},
              {"thickness_used_mm", r.thickness_used_mm},
              {"rim_marker_error_mm", r.rim_marker_error_mm},
              {"rim_points", r.rim_points},
              {"fit_to_bone_used_mm", r.fit_to_bone_used_mm},
              {"seconds", r.seconds}};
}

std::vector<double> unseen_rim_lengths(const std::vector<RimStretch>& stretches) {
  std::vector<double> mm;
  for (const RimStretch& s : stretches) mm.push_back(s.length_mm());
  return mm;
}

Json autoplan_json(const AutoplanResult& r) {
  Json j{{"status", status_name(r.status)},
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
    j["sources"] = Json{{"mirror", r.sources.mirror},
                        {"ring", r.sources.ring},
                        {"with_model", r.sources.with_model},
                        {"none", r.sources.none},
                        {"message", r.sources.describe()}};
    if (r.shape_fit) {
      j["shape_model"] = Json{{"status", status_name(r.shape_fit->status)},
                              {"fitted", r.shape_fit->usable()},
                              {"used", r.method_used == PlanMethod::ShapeModel},
                              {"message", r.shape_fit->message}};
      if (r.shape_fit->measured())
        j["shape_model"].update(Json{{"rms_mm", r.shape_fit->rms_mm},
                                     {"paired", r.shape_fit->paired},
                                     {"mahalanobis", r.shape_fit->mahalanobis}});
    }
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
                           const std::string& session_path, bool all_openings,
                           const std::string& shape_model, AutoplanSession& a) {
  a = autoplan_session(skull, lm, params, output, {}, import, all_openings, shape_model);
  a.session.save(session_path);
  const PlanState& s = a.session.state();
  Json j{{"status", status_name(a.status)}, {"message", a.message}};
  j.update(plan_state_json(s));
  if (s.skull && !s.skull->surface->loaded.warnings.empty())
    j["warnings"] = s.skull->surface->loaded.warnings;
  if (s.skull && !s.skull->surface->loaded.notes.empty())
    j["notes"] = s.skull->surface->loaded.notes;
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
                      const std::string& shape_model, bool json) {
  AutoplanSession first;
  Json j = autoplan_with_session(skull, import, lm, params, output, markers_out, session,
                                 all_openings, shape_model, first);
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
                                     numbered_path(session, k + 2), true, shape_model, a);
    plans.push_back(one);
    all_planned = all_planned && a.planned();
  }
  print_plans(plans, json);
  return all_planned ? kOk : kUnusable;
}

// Writes one automatic plan's markers (if asked for) and implant (if planned, in the
// coordinates the skull's file gave: `space`); its report.
Json write_autoplan(const AutoplanResult& r, const std::string& output,
                    const std::string& markers_out, MeshSpace space) {
  Json j = autoplan_json(r);
  if (!markers_out.empty() && !r.markers.empty()) write_markers_file(r.markers, markers_out);
  if (r.planned()) {
    write_mesh(r.implant.mesh, output, space);
    j["output"] = output;
  }
  return j;
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
  add_declared_options(cmd, o->params);
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
    std::string skull, mirrored, markers, plane, output, method = "shell";
    ImplantParams params;
    MaterialOptions material;
    HoleOptions holes;
    TabOptions tabs;
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
  add_declared_options(cmd, o->params);
  cmd->add_flag("--no-rim-snap", o->no_snap,
                "keep the rim between markers where the spline puts it");
  add_material_options(cmd, o->material);
  add_hole_options(cmd, o->holes);
  add_tab_options(cmd, o->tabs);
  cmd->add_option("--plane", o->plane,
                  "the midsagittal plane (JSON {normal, offset_mm}, as `plane -o` writes): tabs "
                  "keep --tab-midline-distance from it");
  cmd->add_option("-o,--output", o->output, "implant to write (.stl or .ply)")->required();
  return Subcommand{
      cmd, [o, &json] {
        const std::vector<Marker> raw = read_markers_file(o->markers);
        const std::optional<Plane> midline =
            o->plane.empty() ? std::nullopt : std::optional<Plane>(read_plane_file(o->plane));
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
        o->params.material = material_from(o->material);
        o->params.clearance_zones = zones_from(o->material);
        o->params.perforations = perforations_from(o->holes);
        o->params.tabs = tabs_from(o->tabs, o->params.material);
        if (o->params.tabs.any()) o->params.tabs.midline = midline;
        const ImplantResult r = build_implant(snapped.markers, &skull, o->params);
        Json j = implant_json(r);
        j["method"] = o->method;
        j["marker_snap_max_mm"] = snapped.max_distance_mm;
        if (!r.usable()) {
          print_result(j, json);
          return kUnusable;
        }
        write_mesh(r.mesh, o->output, loaded.file_space);
        j["output"] = o->output;
        j["quality"] = to_json(check_implant(r.mesh, &skull, quality_params_for(o->params, r)));
        print_result(j, json);
        return kOk;
      }};
}

// qa
// mould
Subcommand add_mould(CLI::App& app, const bool& json) {
  struct Opts {
    std::string implant, skull, output;
    MouldParams params;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand(
      "mould", "A two-part casting mould of an implant (PMMA in theatre), for FDM printing");
  cmd->add_option("IMPLANT", o->implant, "implant mesh")->required();
  cmd->add_option("--skull", o->skull,
                  "the skull it is made for (its centre tells the implant's outer surface)")
      ->required();
  add_declared_options(cmd, o->params);
  cmd->add_option("-o,--output", o->output,
                  "OUT.3mf (the implant and both halves, named) or OUT.stl (OUT_outer.stl and "
                  "OUT_inner.stl)")
      ->required();
  return Subcommand{
      cmd, [o, &json]() -> int {
        if (const std::string problem = mould_problem(o->params); !problem.empty())
          throw CLI::ValidationError("--wall", problem);
        const MeshFormat format = mesh_format_for_path(o->output);
        if (format == MeshFormat::BinaryPLY)
          throw CLI::ValidationError("--output", "a mould is written as .3mf or .stl");
        const SkullMesh implant = load_surface(o->implant).mesh;
        const LoadedSkull skull = load_skull(o->skull);
        const MouldResult r = make_casting_mould(implant, vertex_centroid(skull.mesh), o->params);
        Json j{{"status", status_name(r.status)},
               {"message", r.message},
               {"cavity_max_mm", r.cavity_max_mm},
               {"cavity_p95_mm", r.cavity_p95_mm},
               {"cavity_beyond_0_2", r.cavity_beyond_0_2},
               {"undercut_mm2", r.undercut_mm2},
               {"trapped_mm2", r.trapped_mm2},
               {"cavity_free_max_mm", r.cavity_free_max_mm},
               {"axis", to_json(r.axis)},
               {"pour", to_json(r.pour)},
               {"vent", to_json(r.vent)},
               {"seconds", r.seconds}};
        if (!r.usable()) {
          print_result(j, json);
          return kUnusable;
        }
        // In the coordinates the skull's file gave (RAS where it declared so).
        const MeshSpace space = skull.file_space;
        if (format == MeshFormat::ThreeMF) {
          const SkullMesh implant_out = mesh_in_space(implant, space),
                          outer = mesh_in_space(r.outer, space),
                          inner = mesh_in_space(r.inner, space);
          write_file_atomically(o->output, encode_3mf({{"implant", &implant_out},
                                                       {"mould outer", &outer},
                                                       {"mould inner", &inner}},
                                                      {{"Application", "Cranioplan"}}));
          j["output"] = o->output;
        } else {
          const std::string stem = o->output.substr(0, o->output.size() - 4);
          write_mesh(r.outer, stem + "_outer.stl", space);
          write_mesh(r.inner, stem + "_inner.stl", space);
          j["output"] = Json::array({stem + "_outer.stl", stem + "_inner.stl"});
        }
        print_result(j, json);
        return kOk;
      }};
}

Subcommand add_qa(CLI::App& app, const bool& json) {
  struct Opts {
    std::string implant, skull, ct, series;
    QualityParams params;
    std::optional<double> min_thickness;
    MaterialOptions material;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("qa", "Quality report of an implant before printing");
  cmd->add_option("IMPLANT", o->implant, "implant mesh")->required();
  cmd->add_option("--skull", o->skull, "the (defective) skull it is made for");
  cmd->add_option("--ct", o->ct,
                  "the patient's CT: also the soft tissue under the implant (brain, dura)");
  add_series_option(cmd, o->series);
  cmd->add_option("--min-thickness", o->min_thickness,
                  "thinnest printable (mm; default the material's, else 1)");
  add_material_options(cmd, o->material, true);
  cmd->add_option("--max-taper", o->params.max_taper_mm,
                  "widest edge on the bone that may be thinner (mm)");
  cmd->add_option("--max-rim-gap", o->params.max_rim_gap_mm, "largest acceptable rim gap (mm)");
  cmd->add_option("--max-penetration", o->params.max_penetration_mm3,
                  "largest acceptable overlap (mm³)");
  return Subcommand{
      cmd, [o, &json] {
        // The material's checks, then the limits given.
        const QualityParams limits = o->params;
        o->params = quality_params_for(material_from(o->material), zones_from(o->material));
        o->params.max_taper_mm = limits.max_taper_mm;
        o->params.max_rim_gap_mm = limits.max_rim_gap_mm;
        o->params.max_penetration_mm3 = limits.max_penetration_mm3;
        if (o->min_thickness) o->params.min_thickness_mm = *o->min_thickness;
        const SkullMesh implant = load_surface(o->implant).mesh;
        SkullMesh skull;
        if (!o->skull.empty()) {
          const LoadedSkull loaded = load_skull(o->skull);
          skull = loaded.mesh;
          // An implant planned up to where the skull's scan ended is cut flat there: no gap to
          // bone is counted along that side, as the plan's own check counts none.
          o->params.scan_ends = scan_ends_met(
              implant, scan_borders(loaded.report ? *loaded.report : report_mesh(skull)));
        }
        const QualityReport q =
            check_implant(implant, o->skull.empty() ? nullptr : &skull, o->params);
        Json j = to_json(q);
        if (!o->ct.empty()) {
          ReadVolumeParams read;
          read.dicom_series = o->series;
          const Volume ct = read_volume(o->ct, read);
          // The cavity's side: the skull's centre, else the CT's.
          Eigen::Vector3d inside =
              ct.world(0.5 * Eigen::Vector3d(ct.dims[0] - 1, ct.dims[1] - 1, ct.dims[2] - 1));
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
                      write_mesh(r.defective, o->output, loaded.file_space);
                      write_mesh(r.implant, o->implant, loaded.file_space);
                      j["defective"] = o->output;
                      j["implant"] = o->implant;
                      print_result(j, json);
                      return kOk;
                    }};
}

// autoplan
Subcommand add_autoplan(CLI::App& app, const bool& json) {
  struct Opts {
    std::string skull, landmarks, output, markers_out, session, method = "auto", shape_model;
    std::vector<double> near;
    bool all_openings = false;
    AutoplanParams params;
    MaterialOptions material;
    HoleOptions holes;
    TabOptions tabs;
    ExtractBoneSurfaceParams import;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd =
      app.add_subcommand("autoplan", "Plan an implant automatically from a defective skull");
  cmd->add_option("SKULL", o->skull, "defective skull (mesh or volume)")->required();
  cmd->add_option("--landmarks", o->landmarks,
                  "landmarks for the midsagittal plane (.json or Slicer .mrk.json)");
  cmd->add_option("--method", o->method,
                  "auto, mirror, rim-only or model (auto: the mirror where it covers the "
                  "opening; elsewhere the shape model when one is given and fits, else the "
                  "ring)")
      ->check(CLI::IsMember({"auto", "mirror", "rim-only", "model"}));
  cmd->add_option("-o,--output", o->output, "implant to write (.stl or .ply)")->required();
  cmd->add_option("--markers-out", o->markers_out,
                  "proposed markers to write (.json, .csv or Slicer .mrk.json)");
  add_shape_model_option(cmd, o->shape_model);
  add_units_option(cmd, o->import.mesh_unit_mm);
  add_series_option(cmd, o->import.dicom_series);
  cmd->add_option("--near", o->near,
                  "X Y Z (mm): with several openings, plan the one in this point's direction "
                  "(default: the largest)")
      ->expected(3);
  add_fit_option(cmd, o->params);
  add_material_options(cmd, o->material);
  add_hole_options(cmd, o->holes);
  add_tab_options(cmd, o->tabs);
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
        o->params.implant.material = material_from(o->material);
        o->params.implant.clearance_zones = zones_from(o->material);
        o->params.implant.perforations = perforations_from(o->holes);
        // The midline is the plan's plane (autoplan sets it).
        o->params.implant.tabs = tabs_from(o->tabs, o->params.implant.material);
        auto markers_path = [&](size_t k) {
          return o->markers_out.empty() ? std::string() : numbered_path(o->markers_out, k);
        };
        const auto model = shape_model_from(o->shape_model);
        if (o->method == "model" && !model)
          throw CLI::ValidationError("--method model", "needs --shape-model FILE");
        if (!o->session.empty())
          return autoplan_sessions(o->skull, o->import, lm, o->params, o->output, o->markers_out,
                                   o->session, o->all_openings, o->shape_model, json);
        const LoadedSkull loaded = load_skull(o->skull, o->import);
        const SkullMesh& skull = loaded.mesh;
        // The reader's warnings (a skull turned outward, non-manifold edges) and notes (a flat
        // cap where the scan ended) with the plan.
        auto with_warnings = [&loaded](Json j) {
          if (!loaded.warnings.empty()) j["warnings"] = loaded.warnings;
          if (!loaded.notes.empty()) j["notes"] = loaded.notes;
          return j;
        };
        if (!o->all_openings) {
          const AutoplanResult r = autoplan(skull, lm, planning(o->params, loaded), model.get());
          print_result(
              with_warnings(write_autoplan(r, o->output, o->markers_out, loaded.file_space)), json);
          return r.planned() ? kOk : kUnusable;
        }
        // Every opening in turn; the first is the one planned without
        // --all-openings.
        const std::vector<AutoplanResult> all =
            autoplan_all_openings(skull, lm, planning(o->params, loaded), model.get());
        if (!all.front().defect.found()) {  // no defect, or no plane
          print_result(with_warnings(write_autoplan(all.front(), o->output, o->markers_out,
                                                    loaded.file_space)),
                       json);
          return all.front().planned() ? kOk : kUnusable;
        }
        Json plans = Json::array();
        bool all_planned = true;
        for (size_t k = 0; k < all.size(); ++k) {
          plans.push_back(with_warnings(write_autoplan(all[k], numbered_path(o->output, k + 1),
                                                       markers_path(k + 1), loaded.file_space)));
          all_planned = all_planned && all[k].planned();
        }
        print_plans(plans, json);
        return all_planned ? kOk : kUnusable;
      }};
}

}  // namespace

std::vector<Subcommand> add_implant_commands(CLI::App& app, const bool& json) {
  return {add_smooth(app, json),        add_implant(app, json),  add_qa(app, json),
          add_mould(app, json),         add_labelmap(app, json), add_compare(app, json),
          add_inject_defect(app, json), add_autoplan(app, json)};
}

}  // namespace cranioplan::cli
