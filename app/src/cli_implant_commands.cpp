#include "cli_implant_commands.h"

#include <memory>
#include <sstream>

#include "cli_output.h"
#include "cranioplan/algorithms/build_implant.h"
#include "cranioplan/algorithms/check_implant.h"
#include "cranioplan/algorithms/compare_implants.h"
#include "cranioplan/algorithms/inject_defect.h"
#include "cranioplan/algorithms/load_skull.h"
#include "cranioplan/algorithms/smooth_markers.h"
#include "cranioplan/algorithms/snap_markers.h"
#include "cranioplan/algorithms/surface_locator.h"
#include "cranioplan/algorithms/write_mesh.h"
#include "cranioplan/model/error.h"
#include "cranioplan/sessions/marker_files.h"

namespace cranioplan::cli {
namespace {

// Meshes, or label volumes (e.g. SkullFix NRRD masks) turned into surfaces with every piece kept.
SkullMesh load_any(const std::string& path) {
  ExtractBoneSurfaceParams p;
  p.largest_piece_only = false;
  p.min_piece_triangles = 1;
  return load_skull(path, p).mesh;
}

Eigen::Vector3d parse_xyz(const std::string& text, const std::string& option) {
  std::stringstream in(text);
  Eigen::Vector3d p;
  char c1 = 0, c2 = 0;
  if (!(in >> p.x() >> c1 >> p.y() >> c2 >> p.z()) || c1 != ',' || c2 != ',' || !p.allFinite())
    throw CLI::ValidationError(option, "expected x,y,z in mm, got '" + text + "'");
  return p;
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

}  // namespace

std::vector<Subcommand> add_implant_commands(CLI::App& app, const bool& json) {
  std::vector<Subcommand> out;

  {  // smooth
    struct Opts {
      std::string markers, output, mirrored;
      SmoothParams params;
    };
    auto o = std::make_shared<Opts>();
    auto* cmd = app.add_subcommand("smooth", "The paper's Laplacian smoother on surface markers");
    cmd->add_option("MARKERS", o->markers, "markers (.json or .csv)")->required();
    cmd->add_option("--radius", o->params.radius_mm, "neighbourhood radius (mm)")->required()->check(CLI::PositiveNumber);
    cmd->add_option("--edge-weight", o->params.edge_weight, "weight of edge markers (>= 1)")->required()->check(CLI::Range(1.0, 1e6));
    cmd->add_option("--iterations", o->params.iterations, "iterations (default 1)")->check(CLI::Range(1, 1000));
    cmd->add_option("--project-onto", o->mirrored, "put smoothed surface markers back onto this mesh (the mirrored skull)");
    cmd->add_option("-o,--output", o->output, "markers to write (.json or .csv)")->required();
    out.push_back({cmd, [o, &json] {
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
      print_result(Json{{"status", ok ? "smoothed" : "too_few_markers"}, {"message", r.message},
                        {"markers", r.markers.size()}, {"max_move_mm", r.max_move_mm}},
                   json);
      return ok ? kOk : kUnusable;
    }});
  }

  {  // implant
    struct Opts {
      std::string skull, mirrored, markers, output, method = "shell";
      ImplantParams params;
      bool no_snap = false;
    };
    auto o = std::make_shared<Opts>();
    auto* cmd = app.add_subcommand("implant", "Build an implant from markers");
    cmd->add_option("--skull", o->skull, "the original (defective) skull")->required();
    cmd->add_option("--mirrored", o->mirrored, "the registered mirrored skull (surface markers are snapped onto it)");
    cmd->add_option("--markers", o->markers, "markers (.json or .csv)")->required();
    cmd->add_option("--method", o->method, "shell (default) or delaunay3d")->check(CLI::IsMember({"shell", "delaunay3d"}));
    cmd->add_option("--resolution", o->params.resolution_mm, "shell edge length (mm)")->check(CLI::Range(0.2, 10.0));
    cmd->add_option("--thickness", o->params.thickness_mm, "thickness without inner markers (mm; default: bone around the rim)")->check(CLI::Range(0.5, 30.0));
    cmd->add_flag("--no-rim-snap", o->no_snap, "keep the rim between markers where the spline puts it");
    cmd->add_option("--alpha", o->params.delaunay_alpha, "delaunay3d alpha (mm; 0 = convex hull)");
    cmd->add_option("--tolerance", o->params.delaunay_tolerance, "delaunay3d tolerance");
    cmd->add_option("--offset", o->params.delaunay_offset, "delaunay3d offset");
    cmd->add_option("-o,--output", o->output, "implant to write (.stl or .ply)")->required();
    out.push_back({cmd, [o, &json] {
      const std::vector<Marker> raw = read_markers_file(o->markers);
      const SkullMesh skull = load_skull(o->skull).mesh;
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
    }});
  }

  {  // qa
    struct Opts {
      std::string implant, skull;
      QualityParams params;
    };
    auto o = std::make_shared<Opts>();
    auto* cmd = app.add_subcommand("qa", "Quality report of an implant before printing");
    cmd->add_option("IMPLANT", o->implant, "implant mesh")->required();
    cmd->add_option("--skull", o->skull, "the (defective) skull it is made for");
    cmd->add_option("--min-thickness", o->params.min_thickness_mm, "thinnest printable (mm)");
    cmd->add_option("--max-rim-gap", o->params.max_rim_gap_mm, "largest acceptable rim gap (mm)");
    cmd->add_option("--max-penetration", o->params.max_penetration_mm3, "largest acceptable overlap (mm³)");
    out.push_back({cmd, [o, &json] {
      const SkullMesh implant = load_skull(o->implant).mesh;
      SkullMesh skull;
      if (!o->skull.empty()) skull = load_skull(o->skull).mesh;
      const QualityReport q = check_implant(implant, o->skull.empty() ? nullptr : &skull, o->params);
      print_result(to_json(q), json);
      return q.printable ? kOk : kUnusable;
    }});
  }

  {  // compare
    struct Opts {
      std::string a, b, skull;
      CompareParams params;
    };
    auto o = std::make_shared<Opts>();
    auto* cmd = app.add_subcommand("compare", "Dice, boundary Dice, HD, HD95 between two implants");
    cmd->add_option("IMPLANT", o->a, "implant (mesh or NRRD/NIfTI mask)")->required();
    cmd->add_option("REFERENCE", o->b, "reference implant (mesh or mask)")->required();
    cmd->add_option("--defective-skull", o->skull, "defective skull for boundary Dice (mesh or mask)");
    cmd->add_option("--spacing", o->params.spacing_mm, "voxel size of the common grid (mm)")->check(CLI::Range(0.1, 2.0));
    out.push_back({cmd, [o, &json] {
      const SkullMesh a = load_any(o->a), b = load_any(o->b);
      SkullMesh skull;
      if (!o->skull.empty()) skull = load_any(o->skull);
      const CompareResult r = compare_implants(a, b, o->skull.empty() ? nullptr : &skull, o->params);
      print_result(to_json(r), json);
      return kOk;
    }});
  }

  {  // inject-defect
    struct Opts {
      std::string skull, center, shape = "sphere", output, implant;
      InjectDefectParams params;
    };
    auto o = std::make_shared<Opts>();
    auto* cmd = app.add_subcommand("inject-defect", "Cut a defect out of a healthy skull, keeping the ground truth");
    cmd->add_option("SKULL", o->skull, "healthy skull (closed mesh or volume)")->required();
    cmd->add_option("--center", o->center, "defect centre x,y,z (mm)")->required();
    cmd->add_option("--size", o->params.size_mm, "sphere diameter or cube edge (mm)")->required()->check(CLI::PositiveNumber);
    cmd->add_option("--shape", o->shape, "sphere or cube")->check(CLI::IsMember({"sphere", "cube"}));
    cmd->add_option("--voxel", o->params.voxel_mm, "resolution of the cut (mm)")->check(CLI::Range(0.1, 2.0));
    cmd->add_option("-o,--output", o->output, "defective skull to write")->required();
    cmd->add_option("--implant", o->implant, "ground-truth implant to write")->required();
    out.push_back({cmd, [o, &json] {
      o->params.center = parse_xyz(o->center, "--center");
      o->params.shape = o->shape == "cube" ? InjectDefectParams::Shape::Cube : InjectDefectParams::Shape::Sphere;
      const SkullMesh skull = load_skull(o->skull).mesh;
      const InjectDefectResult r = inject_defect(skull, o->params);
      Json j{{"status", r.usable() ? "injected" : "no_bone_in_defect"}, {"message", r.message},
             {"removed_volume_mm3", r.removed_volume_mm3}, {"seconds", r.seconds}};
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
    }});
  }
  return out;
}

}  // namespace cranioplan::cli
