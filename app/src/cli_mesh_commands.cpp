#include "cli_mesh_commands.h"

#include <filesystem>
#include <limits>
#include <memory>

#include "cli_output.h"
#include "cranioplan/algorithms/alignment/fit_sagittal_plane.h"
#include "cranioplan/algorithms/alignment/mirror_mesh.h"
#include "cranioplan/algorithms/alignment/register_icp.h"
#include "cranioplan/algorithms/geometry/mesh_components.h"
#include "cranioplan/algorithms/io/load_skull.h"
#include "cranioplan/algorithms/io/mesh_report.h"
#include "cranioplan/algorithms/io/read_mesh.h"
#include "cranioplan/algorithms/io/read_volume.h"
#include "cranioplan/algorithms/io/write_mesh.h"
#include "cranioplan/algorithms/planning/autoplan.h"
#include "cranioplan/model/error.h"

namespace cranioplan::cli {
namespace {

struct ImportOptions {
  double threshold = std::numeric_limits<double>::quiet_NaN();
  long long target_triangles = 0;
  long long all_pieces_above = 0;
  double mesh_unit_mm = 1.0;
  std::string dicom_series;
  ExtractBoneSurfaceParams params() const {
    ExtractBoneSurfaceParams p;
    p.threshold = threshold;
    p.dicom_series = dicom_series;
    p.mesh_unit_mm = mesh_unit_mm;
    p.target_triangles = target_triangles;
    if (all_pieces_above > 0) {
      p.largest_piece_only = false;
      p.min_piece_triangles = all_pieces_above;
    }
    return p;
  }
};

void add_import_options(CLI::App* cmd, ImportOptions& o) {
  cmd->add_option("--threshold", o.threshold,
                  "bone threshold for volumes (default 300 HU for CT, 0.5 for masks)");
  cmd->add_option("--target-triangles", o.target_triangles,
                  "decimate the imported surface to about N triangles (0: full resolution)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--all-pieces-above", o.all_pieces_above,
                  "keep every piece of at least N triangles instead of only the largest")
      ->check(CLI::NonNegativeNumber);
  add_units_option(cmd, o.mesh_unit_mm);
  add_series_option(cmd, o.dicom_series);
}

Json skull_json(const LoadedSkull& s) {
  Json j{{"source", to_string(s.source_kind)},
         {"format", s.description},
         {"frame", s.frame},
         {"load_s", s.seconds}};
  // The coordinate system a mesh file declares (3D Slicer's SPACE=), and whether it was
  // turned to LPS on reading (and so is written back in it).
  if (s.source_kind == SkullSource::Mesh) {
    j["space"] = s.declared_space == MeshSpace::RAS   ? "RAS"
                 : s.declared_space == MeshSpace::LPS ? "LPS"
                                                      : "undeclared";
    j["turned_to_lps"] = s.file_space == MeshSpace::RAS;
  }
  if (s.pieces_dropped > 0) j["pieces_dropped"] = s.pieces_dropped;
  if (s.source_kind == SkullSource::Volume) {
    j["threshold"] = s.surface.threshold_used;
    j["pieces_found"] = s.surface.pieces_found;
    j["pieces_kept"] = s.surface.pieces_kept;
  }
  if (!s.warnings.empty()) j["warnings"] = s.warnings;
  if (!s.notes.empty()) j["notes"] = s.notes;
  return j;
}

struct Pipeline {
  LoadedSkull skull;
  PlaneFit plane;
  SkullMesh mirrored;
  RegisterResult registration;
  SkullMesh registered;
};

// The automatic plan's first stages (autoplan_stages), with the meshes they imply.
Pipeline run_pipeline(const std::string& input, const ImportOptions& import,
                      const std::string& landmarks_path) {
  Pipeline p;
  const Landmarks lm = landmarks_path.empty() ? Landmarks{} : read_landmarks_file(landmarks_path);
  p.skull = load_skull(input, import.params());
  const AutoplanParams params;
  p.plane = autoplan_stages::plane(p.skull.mesh, lm, params);
  if (!p.plane.usable()) return p;
  p.mirrored = mirror_mesh(p.skull.mesh, p.plane.plane);
  p.registration = autoplan_stages::registration(p.skull.mesh, p.plane.plane, params);
  if (p.registration.usable()) p.registered = transform_mesh(p.mirrored, p.registration.transform);
  return p;
}

// info: a mesh's or a volume's bone surface's report
Subcommand add_info(CLI::App& app, const bool& json) {
  struct Opts {
    std::string path;
    ImportOptions import;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("info", "Report a mesh (or a volume's bone surface)");
  cmd->add_option("MESH", o->path, "mesh (.stl .ply .obj .off .vtk .vtp) or volume")->required();
  add_import_options(cmd, o->import);
  return {cmd, [o, &json] {
            LoadedSkull s = load_surface(o->path, o->import.params());
            Json r = to_json(report_mesh(s.mesh));
            // The file as it is; read as a skull, it is repaired (load_skull) on the file's own
            // triangles: what that would do, which a non-manifold count alone would misname.
            TriangleSoup soup =
                s.source_kind == SkullSource::Mesh ? read_mesh_soup(o->path) : to_soup(s.mesh);
            const SoupRepair repairs = repair_soup(soup, skull_repairs(o->import.params()));
            r["repeated_triangles"] = repairs.repeated_dropped;
            r["wound_against_neighbours"] = {{"triangles", repairs.orientation.triangles_turned},
                                             {"patches", repairs.orientation.patches_turned}};
            r["small_holes"] = repairs.holes.closed;
            for (const std::string& sentence : describe_repairs(repairs))
              s.warnings.push_back(
                  o->path + ": read as a skull (autoplan, pipeline, the wizard), " + sentence);
            r["file"] = skull_json(s);
            print_warnings(s.warnings, json);
            print_result(r, json);
            return kOk;
          }};
}

// import-ct: a CT's or a label volume's bone surface, written as a mesh
Subcommand add_import_ct(CLI::App& app, const bool& json) {
  struct Opts {
    std::string path, output;
    ImportOptions import;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("import-ct", "Turn a CT or label volume into a bone surface");
  cmd->add_option("VOLUME", o->path, ".inv3, .nrrd/.nhdr, .nii/.nii.gz or a DICOM folder")
      ->required();
  cmd->add_option("-o,--output", o->output, "mesh to write (.stl or .ply)")->required();
  add_import_options(cmd, o->import);
  return {cmd, [o, &json] {
            std::error_code ec;
            if (!std::filesystem::exists(o->path, ec))
              throw InputError(o->path, "does not exist (no such file or folder)");
            if (!is_volume_path(o->path))
              throw InputError(o->path,
                               "is not a volume (expected .inv3, .nrrd, .nhdr, .nii, .nii.gz "
                               "or a DICOM folder)");
            const LoadedSkull s = load_surface(o->path, o->import.params());
            write_mesh(s.mesh, o->output);
            Json r = skull_json(s);
            r["o->output"] = o->output;
            r["mesh"] = to_json(report_mesh(s.mesh));
            print_result(r, json);
            return kOk;
          }};
}

// plane: the midsagittal plane
Subcommand add_plane(CLI::App& app, const bool& json) {
  struct Opts {
    std::string mesh, landmarks, output;
    bool no_refine = false;
    ImportOptions import;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("plane", "Fit the midsagittal plane");
  cmd->add_option("MESH", o->mesh, "skull mesh or volume")->required();
  cmd->add_option(
      "--landmarks", o->landmarks,
      "landmarks (nasion, orbit_left, orbit_right, midline; .json or Slicer .mrk.json)");
  cmd->add_flag("--no-refine", o->no_refine,
                "only the initial plane, without the Ceres refinement");
  cmd->add_option("-o,--output", o->output, "plane JSON to write");
  add_import_options(cmd, o->import);
  return {cmd, [o, &json] {
            const Landmarks lm =
                o->landmarks.empty() ? Landmarks{} : read_landmarks_file(o->landmarks);
            const LoadedSkull s = load_skull(o->mesh, o->import.params());
            PlaneFitParams params;
            params.refine = !o->no_refine;
            const PlaneFit fit = fit_sagittal_plane(s.mesh, lm, params);
            Json r = to_json(fit);
            if (!s.warnings.empty()) r["warnings"] = s.warnings;
            if (!fit.usable()) {
              print_result(r, json);
              return kUnusable;
            }
            if (!o->output.empty()) write_json_file(to_json(fit.plane), o->output);
            print_result(r, json);
            return kOk;
          }};
}

// mirror: a mesh mirrored across a plane
Subcommand add_mirror(CLI::App& app, const bool& json) {
  struct Opts {
    std::string mesh, plane, output;
    ImportOptions import;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("mirror", "Mirror a mesh across a plane");
  cmd->add_option("MESH", o->mesh, "mesh or volume")->required();
  cmd->add_option("--plane", o->plane, "plane JSON {normal, offset_mm}")->required();
  cmd->add_option("-o,--output", o->output, "mesh to write (.stl or .ply)")->required();
  add_import_options(cmd, o->import);
  return {
      cmd, [o, &json] {
        const Plane p = read_plane_file(o->plane);
        const LoadedSkull s = load_skull(o->mesh, o->import.params());
        const SkullMesh m = mirror_mesh(s.mesh, p);
        write_mesh(m, o->output, s.file_space);
        Json r{{"o->output", o->output}, {"plane", to_json(p)}, {"mesh", to_json(report_mesh(m))}};
        if (!s.warnings.empty()) r["warnings"] = s.warnings;
        print_result(r, json);
        return kOk;
      }};
}

// register: one mesh rigidly onto another
Subcommand add_register(CLI::App& app, const bool& json) {
  struct Opts {
    std::string moving, fixed, output, roi_center, roi_half_size;
    double roi_radius = 0.0;
    ImportOptions import;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd =
      app.add_subcommand("register", "Rigidly register MOVING onto FIXED (point-to-plane ICP)");
  cmd->add_option("MOVING", o->moving, "mesh to move")->required();
  cmd->add_option("FIXED", o->fixed, "mesh to move onto")->required();
  cmd->add_option("-o,--output", o->output, "write MOVING after the transform");
  cmd->add_option("--roi-center", o->roi_center, "region of interest centre x,y,z (mm)");
  cmd->add_option("--roi-radius", o->roi_radius, "spherical region radius (mm)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--roi-half-size", o->roi_half_size, "box region half extents x,y,z (mm)");
  add_import_options(cmd, o->import);
  return {cmd, [o, &json] {
            RegisterParams params;
            if (!o->roi_center.empty()) {
              RegionOfInterest roi;
              roi.center = parse_point(o->roi_center, "--roi-center");
              if (!o->roi_half_size.empty()) {
                roi.shape = RegionOfInterest::Shape::Box;
                roi.half_size = parse_point(o->roi_half_size, "--roi-half-size");
              } else if (o->roi_radius > 0) {
                roi.radius = o->roi_radius;
              } else {
                throw CLI::ValidationError("--roi-center", "needs --roi-radius or --roi-half-size");
              }
              params.roi = roi;
            }
            const LoadedSkull moving = load_surface(o->moving, o->import.params());
            const LoadedSkull fixed = load_surface(o->fixed, o->import.params());
            const RegisterResult r = register_icp(moving.mesh, fixed.mesh, params);
            Json j = to_json(r);
            if (!r.usable()) {
              print_result(j, json);
              return kUnusable;
            }
            if (!o->output.empty()) {
              // Onto the fixed surface, in the coordinates its file gave.
              write_mesh(transform_mesh(moving.mesh, r.transform), o->output, fixed.file_space);
              j["o->output"] = o->output;
            }
            print_result(j, json);
            return kOk;
          }};
}

// pipeline: the automatic plan's first stages, their meshes written to a folder
Subcommand add_pipeline(CLI::App& app, const bool& json) {
  struct Opts {
    std::string input, landmarks, output;
    bool use_sample = false;
    ImportOptions import;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand(
      "pipeline", "Import, fit the plane, mirror and register; write the meshes to a folder");
  cmd->add_option("INPUT", o->input, "skull mesh or volume (default: the sample case)");
  cmd->add_flag("--sample", o->use_sample, "use the installed sample case (Cranium.inv3)");
  cmd->add_option("--landmarks", o->landmarks, "landmarks (.json or Slicer .mrk.json)");
  cmd->add_option("-o,--output", o->output, "output folder")->required();
  add_import_options(cmd, o->import);
  return {cmd, [o, &json] {
            const std::string input =
                o->use_sample || o->input.empty() ? sample_case_path() : o->input;
            std::filesystem::create_directories(o->output);
            const Pipeline p = run_pipeline(input, o->import, o->landmarks);
            const std::filesystem::path dir(o->output);
            // The meshes in the coordinates the input gave (RAS where it declared so), the plane
            // and the transform in the plan's LPS frame.
            const MeshSpace space = p.skull.file_space;
            write_mesh(p.skull.mesh, (dir / "skull.stl").string(), space);
            Json r{{"input", input},
                   {"skull", skull_json(p.skull)},
                   {"mesh", to_json(report_mesh(p.skull.mesh))}};
            r["plane"] = to_json(p.plane);
            if (!p.plane.usable()) {
              print_result(r, json);
              return kUnusable;
            }
            write_json_file(to_json(p.plane.plane), (dir / "plane.json").string());
            write_mesh(p.mirrored, (dir / "mirrored.stl").string(), space);
            r["registration"] = to_json(p.registration);
            if (!p.registration.usable()) {
              print_result(r, json);
              return kUnusable;
            }
            write_json_file(to_json(p.registration.transform), (dir / "transform.json").string());
            write_mesh(p.registered, (dir / "mirrored_registered.stl").string(), space);
            r["outputs"] = {(dir / "skull.stl").string(), (dir / "plane.json").string(),
                            (dir / "mirrored.stl").string(), (dir / "transform.json").string(),
                            (dir / "mirrored_registered.stl").string()};
            print_result(r, json);
            return kOk;
          }};
}

// series: the DICOM series of a folder
Subcommand add_series(CLI::App& app, const bool& json) {
  auto folder = std::make_shared<std::string>();
  auto* cmd = app.add_subcommand("series", "List the DICOM series of a folder");
  cmd->add_option("FOLDER", *folder, "folder of DICOM files (searched 8 deep)")->required();
  return {cmd, [folder, &json] {
            Json list = Json::array();
            for (const DicomSeries& d : list_dicom_series(*folder))
              list.push_back({{"uid", d.uid},
                              {"modality", d.modality},
                              {"description", d.description},
                              {"columns", d.columns},
                              {"rows", d.rows},
                              {"slices", d.slices}});
            print_result(Json{{"folder", *folder}, {"series", list}}, json);
            return list.empty() ? kUnusable : kOk;
          }};
}

}  // namespace

std::vector<Subcommand> add_mesh_commands(CLI::App& app, const bool& json) {
  return {add_info(app, json),   add_import_ct(app, json), add_plane(app, json),
          add_mirror(app, json), add_register(app, json),  add_pipeline(app, json),
          add_series(app, json)};
}

}  // namespace cranioplan::cli
