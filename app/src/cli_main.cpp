// cranioplan-cli: the planning pipeline without a window. Exit codes: 0 success, 1 the
// computation gave no usable result (its status says why), 2 usage error, 3 bad input file.
#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "cli_bench.h"
#include "cli_implant_commands.h"
#include "cli_output.h"
#include "cli_session_commands.h"
#include "cranioplan/algorithms/fit_sagittal_plane.h"
#include "cranioplan/algorithms/load_skull.h"
#include "cranioplan/algorithms/mesh_report.h"
#include "cranioplan/algorithms/mirror_mesh.h"
#include "cranioplan/algorithms/read_volume.h"
#include "cranioplan/algorithms/register_icp.h"
#include "cranioplan/algorithms/write_mesh.h"
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
  Json j{{"source", s.source_kind},
         {"format", s.description},
         {"frame", s.frame},
         {"load_s", s.seconds}};
  if (s.pieces_dropped > 0) j["pieces_dropped"] = s.pieces_dropped;
  if (s.source_kind == "volume") {
    j["threshold"] = s.surface.threshold_used;
    j["pieces_found"] = s.surface.pieces_found;
    j["pieces_kept"] = s.surface.pieces_kept;
  }
  if (!s.warnings.empty()) j["warnings"] = s.warnings;
  return j;
}

struct Pipeline {
  LoadedSkull skull;
  PlaneFit plane;
  SkullMesh mirrored;
  RegisterResult registration;
  SkullMesh registered;
};

Pipeline run_pipeline(const std::string& input, const ImportOptions& import,
                      const std::string& landmarks_path) {
  Pipeline p;
  const Landmarks lm = landmarks_path.empty() ? Landmarks{} : read_landmarks_file(landmarks_path);
  p.skull = load_skull(input, import.params());
  p.plane = fit_sagittal_plane(p.skull.mesh, lm);
  if (!p.plane.usable()) return p;
  p.mirrored = mirror_mesh(p.skull.mesh, p.plane.plane);
  p.registration = register_icp(p.mirrored, p.skull.mesh);
  if (p.registration.usable()) p.registered = transform_mesh(p.mirrored, p.registration.transform);
  return p;
}

}  // namespace

int run(int argc, char** argv) {
  CLI::App app{"cranioplan-cli " CRANIOPLAN_VERSION
               " — patient-specific cranial implant planning without a window.\n"
               "Exit codes: 0 success, 1 no usable result, 2 usage error, 3 bad input file."};
  app.require_subcommand(1);
  app.set_version_flag("--version", CRANIOPLAN_VERSION);
  bool json = false;
  std::string output;
  ImportOptions import;

  // info
  std::string info_path;
  auto* info = app.add_subcommand("info", "Report a mesh (or a volume's bone surface)");
  info->add_option("MESH", info_path, "mesh (.stl .ply .obj .off .vtp) or volume")->required();
  add_import_options(info, import);

  // import-ct
  std::string ct_path;
  auto* import_ct =
      app.add_subcommand("import-ct", "Turn a CT or label volume into a bone surface");
  import_ct->add_option("VOLUME", ct_path, ".inv3, .nrrd/.nhdr, .nii/.nii.gz or a DICOM folder")
      ->required();
  import_ct->add_option("-o,--output", output, "mesh to write (.stl or .ply)")->required();
  add_import_options(import_ct, import);

  // plane
  std::string plane_mesh, landmarks_path;
  bool no_refine = false;
  auto* plane = app.add_subcommand("plane", "Fit the midsagittal plane");
  plane->add_option("MESH", plane_mesh, "skull mesh or volume")->required();
  plane->add_option("--landmarks", landmarks_path,
                    "landmarks JSON (nasion, orbit_left, orbit_right, midline)");
  plane->add_flag("--no-refine", no_refine, "only the initial plane, without the Ceres refinement");
  plane->add_option("-o,--output", output, "plane JSON to write");
  add_import_options(plane, import);

  // mirror
  std::string mirror_mesh_path, plane_path;
  auto* mirror = app.add_subcommand("mirror", "Mirror a mesh across a plane");
  mirror->add_option("MESH", mirror_mesh_path, "mesh or volume")->required();
  mirror->add_option("--plane", plane_path, "plane JSON {normal, offset_mm}")->required();
  mirror->add_option("-o,--output", output, "mesh to write (.stl or .ply)")->required();
  add_import_options(mirror, import);

  // register
  std::string moving_path, fixed_path, roi_center, roi_half_size;
  double roi_radius = 0.0;
  auto* reg =
      app.add_subcommand("register", "Rigidly register MOVING onto FIXED (point-to-plane ICP)");
  reg->add_option("MOVING", moving_path, "mesh to move")->required();
  reg->add_option("FIXED", fixed_path, "mesh to move onto")->required();
  reg->add_option("-o,--output", output, "write MOVING after the transform");
  reg->add_option("--roi-center", roi_center, "region of interest centre x,y,z (mm)");
  reg->add_option("--roi-radius", roi_radius, "spherical region radius (mm)")
      ->check(CLI::PositiveNumber);
  reg->add_option("--roi-half-size", roi_half_size, "box region half extents x,y,z (mm)");
  add_import_options(reg, import);

  // pipeline
  std::string pipeline_input;
  bool use_sample = false;
  auto* pipeline = app.add_subcommand(
      "pipeline", "Import, fit the plane, mirror and register; write the meshes to a folder");
  pipeline->add_option("INPUT", pipeline_input, "skull mesh or volume (default: the sample case)");
  pipeline->add_flag("--sample", use_sample, "use the installed sample case (Cranium.inv3)");
  pipeline->add_option("--landmarks", landmarks_path, "landmarks JSON");
  pipeline->add_option("-o,--output", output, "output folder")->required();
  add_import_options(pipeline, import);

  // series
  std::string series_folder;
  auto* series = app.add_subcommand("series", "List the DICOM series of a folder");
  series->add_option("FOLDER", series_folder, "folder of DICOM files (searched 8 deep)")
      ->required();

  // bench
  BenchOptions bench_options;
  auto* bench = app.add_subcommand("bench", "Time the pipeline's steps on the sample case");
  bench->add_option("--input", bench_options.input, "volume or mesh instead of the sample case");
  bench->add_option("--runs", bench_options.runs, "repetitions per step (median reported)")
      ->check(CLI::Range(1, 100));

  std::vector<Subcommand> implant_commands = add_implant_commands(app, json);
  for (auto& c : add_session_commands(app, json)) implant_commands.push_back(std::move(c));

  for (auto* sub : app.get_subcommands([](CLI::App*) { return true; }))
    sub->add_flag("--json", json, "print one JSON object on stdout");

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kUsage;
  }

  try {
    if (info->parsed()) {
      const LoadedSkull s = load_surface(info_path, import.params());
      Json r = to_json(report_mesh(s.mesh));
      r["file"] = skull_json(s);
      print_warnings(s.warnings, json);
      print_result(r, json);
      return kOk;
    }
    if (series->parsed()) {
      Json list = Json::array();
      for (const DicomSeries& d : list_dicom_series(series_folder))
        list.push_back({{"uid", d.uid},
                        {"modality", d.modality},
                        {"description", d.description},
                        {"columns", d.columns},
                        {"rows", d.rows},
                        {"slices", d.slices}});
      print_result(Json{{"folder", series_folder}, {"series", list}}, json);
      return list.empty() ? kUnusable : kOk;
    }
    if (import_ct->parsed()) {
      std::error_code ec;
      if (!std::filesystem::exists(ct_path, ec))
        throw InputError(ct_path, "does not exist (no such file or folder)");
      if (!is_volume_path(ct_path))
        throw InputError(ct_path,
                         "is not a volume (expected .inv3, .nrrd, .nhdr, .nii, .nii.gz "
                         "or a DICOM folder)");
      const LoadedSkull s = load_surface(ct_path, import.params());
      write_mesh(s.mesh, output);
      Json r = skull_json(s);
      r["output"] = output;
      r["mesh"] = to_json(report_mesh(s.mesh));
      print_result(r, json);
      return kOk;
    }
    if (plane->parsed()) {
      const Landmarks lm =
          landmarks_path.empty() ? Landmarks{} : read_landmarks_file(landmarks_path);
      const LoadedSkull s = load_skull(plane_mesh, import.params());
      PlaneFitParams params;
      params.refine = !no_refine;
      const PlaneFit fit = fit_sagittal_plane(s.mesh, lm, params);
      Json r = to_json(fit);
      if (!s.warnings.empty()) r["warnings"] = s.warnings;
      if (!fit.usable()) {
        print_result(r, json);
        return kUnusable;
      }
      if (!output.empty()) write_json_file(to_json(fit.plane), output);
      print_result(r, json);
      return kOk;
    }
    if (mirror->parsed()) {
      const Plane p = read_plane_file(plane_path);
      const LoadedSkull s = load_skull(mirror_mesh_path, import.params());
      const SkullMesh m = mirror_mesh(s.mesh, p);
      write_mesh(m, output);
      Json r{{"output", output}, {"plane", to_json(p)}, {"mesh", to_json(report_mesh(m))}};
      if (!s.warnings.empty()) r["warnings"] = s.warnings;
      print_result(r, json);
      return kOk;
    }
    if (reg->parsed()) {
      RegisterParams params;
      if (!roi_center.empty()) {
        RegionOfInterest roi;
        roi.center = parse_point(roi_center, "--roi-center");
        if (!roi_half_size.empty()) {
          roi.shape = RegionOfInterest::Shape::Box;
          roi.half_size = parse_point(roi_half_size, "--roi-half-size");
        } else if (roi_radius > 0) {
          roi.radius = roi_radius;
        } else {
          throw CLI::ValidationError("--roi-center", "needs --roi-radius or --roi-half-size");
        }
        params.roi = roi;
      }
      const LoadedSkull moving = load_surface(moving_path, import.params());
      const LoadedSkull fixed = load_surface(fixed_path, import.params());
      const RegisterResult r = register_icp(moving.mesh, fixed.mesh, params);
      Json j = to_json(r);
      if (!r.usable()) {
        print_result(j, json);
        return kUnusable;
      }
      if (!output.empty()) {
        write_mesh(transform_mesh(moving.mesh, r.transform), output);
        j["output"] = output;
      }
      print_result(j, json);
      return kOk;
    }
    if (pipeline->parsed()) {
      const std::string input =
          use_sample || pipeline_input.empty() ? sample_case_path() : pipeline_input;
      std::filesystem::create_directories(output);
      const Pipeline p = run_pipeline(input, import, landmarks_path);
      const std::filesystem::path dir(output);
      write_mesh(p.skull.mesh, (dir / "skull.stl").string());
      Json r{{"input", input},
             {"skull", skull_json(p.skull)},
             {"mesh", to_json(report_mesh(p.skull.mesh))}};
      r["plane"] = to_json(p.plane);
      if (!p.plane.usable()) {
        print_result(r, json);
        return kUnusable;
      }
      write_json_file(to_json(p.plane.plane), (dir / "plane.json").string());
      write_mesh(p.mirrored, (dir / "mirrored.stl").string());
      r["registration"] = to_json(p.registration);
      if (!p.registration.usable()) {
        print_result(r, json);
        return kUnusable;
      }
      write_json_file(to_json(p.registration.transform), (dir / "transform.json").string());
      write_mesh(p.registered, (dir / "mirrored_registered.stl").string());
      r["outputs"] = {(dir / "skull.stl").string(), (dir / "plane.json").string(),
                      (dir / "mirrored.stl").string(), (dir / "transform.json").string(),
                      (dir / "mirrored_registered.stl").string()};
      print_result(r, json);
      return kOk;
    }
    if (bench->parsed()) {
      print_result(run_bench(bench_options), json);
      return kOk;
    }
    for (const auto& c : implant_commands)
      if (c.app->parsed()) return c.run();
  } catch (const CLI::ValidationError& e) {
    print_error(e.what(), kUsage, json);
    return kUsage;
  } catch (const InputError& e) {
    print_error(e.what(), kBadInput, json);
    return kBadInput;
  } catch (const Error& e) {
    print_error(e.what(), kBadInput, json);
    return kBadInput;
  } catch (const std::filesystem::filesystem_error& e) {
    print_error(e.what(), kBadInput, json);
    return kBadInput;
  } catch (const std::bad_alloc&) {
    print_error("out of memory", kUnusable, json);
    return kUnusable;
  } catch (const std::exception& e) {  // a defect of ours: said, not an abort
    print_error(std::string("unexpected error (please report it): ") + e.what(), kUnusable, json);
    return kUnusable;
  }
  return kUsage;
}

}  // namespace cranioplan::cli

int main(int argc, char** argv) { return cranioplan::cli::run(argc, argv); }
