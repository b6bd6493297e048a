#include "cli_bench.h"

#include <sys/resource.h>
#include <unistd.h>
#include <vtkDataSetSurfaceFilter.h>
#include <vtkDelaunay3D.h>
#include <vtkIterativeClosestPointTransform.h>
#include <vtkLandmarkTransform.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSTLReader.h>
#include <vtkSmoothPolyDataFilter.h>
#include <vtkTransform.h>
#include <vtkTransformPolyDataFilter.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <functional>
#include <memory>

#include "cli_output.h"
#include "cranioplan/algorithms/alignment/fit_sagittal_plane.h"
#include "cranioplan/algorithms/alignment/mirror_mesh.h"
#include "cranioplan/algorithms/alignment/register_icp.h"
#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/io/load_skull.h"
#include "cranioplan/algorithms/io/read_mesh.h"
#include "cranioplan/algorithms/io/write_mesh.h"
#include "cranioplan/algorithms/planning/autoplan.h"
#include "cranioplan/sessions/autoplan_session.h"
#include "cranioplan/sessions/previews.h"

namespace cranioplan::cli {
namespace {

double median_seconds(int runs, const std::function<void()>& step) {
  std::vector<double> t;
  for (int i = 0; i < runs; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    step();
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

// The seed paper's steps written with plain VTK, as the reference the plan's speed is measured
// against (it gives no usable implant): read the STL, mirror it across the plane, register the
// mirror with VTK's ICP, triangulate the markers with Delaunay 3D and smooth the result.
void vtk_reference_pipeline(const std::string& stl, const Plane& plane,
                            const std::vector<Marker>& markers) {
  vtkNew<vtkSTLReader> reader;
  reader->SetFileName(stl.c_str());
  reader->Update();
  // The reflection x ↦ x − 2 (n·x − d) n as a 4×4 matrix.
  const Eigen::Vector3d n = plane.normal;
  vtkNew<vtkTransform> reflect;
  double m[16] = {0};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m[4 * r + c] = (r == c ? 1.0 : 0.0) - 2.0 * n[r] * n[c];
    m[4 * r + 3] = 2.0 * plane.offset * n[r];
  }
  m[15] = 1.0;
  reflect->SetMatrix(m);
  vtkNew<vtkTransformPolyDataFilter> mirror;
  mirror->SetInputConnection(reader->GetOutputPort());
  mirror->SetTransform(reflect);
  mirror->Update();
  vtkNew<vtkIterativeClosestPointTransform> icp;
  icp->SetSource(mirror->GetOutput());
  icp->SetTarget(reader->GetOutput());
  icp->GetLandmarkTransform()->SetModeToRigidBody();
  icp->SetMaximumNumberOfIterations(50);
  icp->SetMaximumNumberOfLandmarks(2000);
  icp->Update();
  vtkNew<vtkTransformPolyDataFilter> registered;
  registered->SetInputConnection(mirror->GetOutputPort());
  registered->SetTransform(icp);
  registered->Update();
  vtkNew<vtkPoints> points;
  for (const Marker& k : markers) points->InsertNextPoint(k.position.data());
  vtkNew<vtkPolyData> cloud;
  cloud->SetPoints(points);
  vtkNew<vtkDelaunay3D> delaunay;
  delaunay->SetInputData(cloud);
  vtkNew<vtkDataSetSurfaceFilter> surface;
  surface->SetInputConnection(delaunay->GetOutputPort());
  vtkNew<vtkSmoothPolyDataFilter> smooth;
  smooth->SetInputConnection(surface->GetOutputPort());
  smooth->SetNumberOfIterations(20);
  smooth->Update();
}

double peak_rss_mb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;  // Linux reports kilobytes
}

}  // namespace

// Reading: the import of the input, and its STL read by the project and by VTK.
LoadedSkull bench_reading(const std::string& input, int runs, Json& out) {
  LoadedSkull skull;
  out["import_s"] = median_seconds(runs, [&] { skull = load_skull(input); });
  out["triangles"] = skull.mesh.n_faces();
  out["vertices"] = skull.mesh.n_vertices();

  const std::filesystem::path tmp = std::filesystem::temp_directory_path() /
                                    ("cranioplan-bench-" + std::to_string(::getpid()) + ".stl");
  write_mesh(skull.mesh, tmp.string(), MeshFormat::BinarySTL);
  out["stl_load_s"] = median_seconds(runs, [&] { read_mesh(tmp.string()); });
  out["stl_parse_weld_s"] = median_seconds(runs, [&] { read_mesh_soup(tmp.string()); });
  out["vtk_stl_reader_s"] = median_seconds(runs, [&] {
    vtkNew<vtkSTLReader> reader;
    reader->SetFileName(tmp.string().c_str());
    reader->Update();
  });
  // Like for like: vtkSTLReader gives merged points and a triangle list, as read_mesh_soup does;
  // read_mesh also builds OpenMesh's halfedge structure.
  out["stl_speedup_vs_vtk"] =
      out["vtk_stl_reader_s"].get<double>() / out["stl_parse_weld_s"].get<double>();
  out["stl_load_with_halfedges_speedup_vs_vtk"] =
      out["vtk_stl_reader_s"].get<double>() / out["stl_load_s"].get<double>();
  std::filesystem::remove(tmp);
  return skull;
}

// The plane, the mirror and its registration, each alone.
void bench_alignment(const LoadedSkull& skull, int runs, Json& out) {
  PlaneFit fit;
  out["plane_s"] = median_seconds(runs, [&] { fit = fit_sagittal_plane(skull.mesh, Landmarks{}); });
  SkullMesh mirrored;
  out["mirror_s"] = median_seconds(runs, [&] { mirrored = mirror_mesh(skull.mesh, fit.plane); });
  RegisterResult reg;
  out["register_s"] = median_seconds(runs, [&] { reg = register_icp(mirrored, skull.mesh); });
  out["plane_mirror_register_s"] = out["plane_s"].get<double>() + out["mirror_s"].get<double>() +
                                   out["register_s"].get<double>();
  out["symmetry_rms_mm"] = fit.symmetry_rms_mm;
  out["register_rms_mm"] = reg.rms_mm;
}

// The wizard's inner loop: smooth the markers and rebuild the shell after a marker edit, with
// the skull's and the mirror's locators built once; on at least 300 markers, as a dense manual
// plan has (re-planned with closer spacing if needed). Whether the re-plan was made.
bool bench_editing(const LoadedSkull& skull, AutoplanResult plan, int runs, Json& out) {
  AutoplanParams dense;
  for (double spacing = 5.0; plan.markers.size() < 300 && spacing >= 2.0; spacing -= 1.0) {
    dense.propose.surface_spacing_mm = spacing;
    dense.propose.edge_spacing_mm = std::min(4.0, spacing);
    plan = autoplan(skull.mesh, Landmarks{}, dense);
  }
  const SurfaceLocator bone(skull.mesh), mirror = bone.moved(plan.mirror_motion);
  out["skull_locator_mb"] = static_cast<double>(bone.memory_bytes()) / 1e6;
  out["edit_markers"] = plan.markers.size();
  // While markers are edited the shell is rebuilt as it stands (the wizard's live preview);
  // fitting it to the bone (automatic plans, and the wizard's "Fit to the bone") costs more.
  ImplantParams live = AutoplanParams{}.implant;
  live.fit_to_bone_mm = 0.0;
  out["smooth_and_rebuild_s"] = median_seconds(runs, [&] {
    const SmoothResult s = smooth_markers(plan.markers, SmoothParams{10.0, 2.0, 1}, &mirror);
    build_implant(s.markers, &skull.mesh, &bone, live);
  });
  // The fitted rebuild's stages (ImplantResult::stage_seconds), each the median of the runs:
  // where a committed drag's time goes.
  std::vector<std::vector<std::pair<std::string, double>>> stages;
  out["smooth_and_rebuild_fitted_s"] = median_seconds(runs, [&] {
    const SmoothResult s = smooth_markers(plan.markers, SmoothParams{10.0, 2.0, 1}, &mirror);
    stages.push_back(
        build_implant(s.markers, &skull.mesh, &bone, AutoplanParams{}.implant).stage_seconds);
  });
  Json profile = Json::object();
  for (size_t k = 0; !stages.empty() && k < stages.front().size(); ++k) {
    std::vector<double> t;
    for (const auto& run : stages)
      if (k < run.size() && run[k].first == stages.front()[k].first) t.push_back(run[k].second);
    std::sort(t.begin(), t.end());
    if (!t.empty()) profile[stages.front()[k].first] = t[t.size() / 2];
  }
  out["fitted_rebuild_stages_s"] = profile;
  return plan.planned();
}

// The same plan as session commands: one marker drag (the implant follows), then undo and redo
// of it, which the session serves from its cache of states.
void bench_session(const std::string& input, int runs, Json& out) {
  AutoplanSession a = autoplan_session(input, Landmarks{}, AutoplanParams{}, "");
  if (!a.planned() || a.session.state().markers.empty()) return;
  Session& session = a.session;
  const Marker m = session.state().markers.back();
  const SurfaceLocator& surface = m.surface == MarkerSurface::Mirrored
                                      ? session.state().mirrored->locator
                                      : session.state().skull->surface->locator;
  int k = 0;
  out["session_move_marker_s"] = median_seconds(runs, [&] {
    const Eigen::Vector3d to = surface.closest(m.position + Eigen::Vector3d(0, 0, 0.2 * ++k)).point;
    session.push(commands::note("separates the drags"));
    session.push(commands::move_marker(m.id, to));
  });
  // What the wizard does for every mouse move while the marker is dragged: the same move
  // applied with the implant previewed without the fit (the fitted one is computed on a worker
  // once the marker is let go).
  if (session.state().implant_params) {
    int n = 0;
    out["drag_preview_s"] = median_seconds(runs, [&] {
      const Eigen::Vector3d to =
          surface.closest(m.position + Eigen::Vector3d(0, 0.2 * ++n, 0)).point;
      preview_command_quickly(session.state(), commands::move_marker(m.id, to), session.context());
    });
  }
  out["session_undo_s"] = median_seconds(runs,
                                         [&] {
                                           session.undo();
                                           session.redo();
                                         }) /
                          2.0;
  out["session_commands"] = session.index();
}

Json run_bench(const BenchOptions& options) {
  const std::string input = options.input.empty() ? sample_case_path() : options.input;
  const int runs = std::max(1, options.runs);
  Json out;
  out["input"] = input;
  out["runs"] = runs;
  const LoadedSkull skull = bench_reading(input, runs, out);
  bench_alignment(skull, runs, out);
  AutoplanResult plan;
  out["autoplan_s"] = median_seconds(1, [&] { plan = autoplan(skull.mesh, Landmarks{}); });
  if (plan.planned()) {
    // The paper's steps in plain VTK on the same skull, plane and markers, in the same run.
    const std::filesystem::path tmp = std::filesystem::temp_directory_path() /
                                      ("cranioplan-bench-" + std::to_string(::getpid()) + ".stl");
    write_mesh(skull.mesh, tmp.string(), MeshFormat::BinarySTL);
    out["vtk_reference_s"] = median_seconds(
        runs, [&] { vtk_reference_pipeline(tmp.string(), plan.plane.plane, plan.markers); });
    std::filesystem::remove(tmp);
    out["autoplan_over_vtk_reference"] =
        out["autoplan_s"].get<double>() / out["vtk_reference_s"].get<double>();
    if (bench_editing(skull, std::move(plan), runs, out)) bench_session(input, runs, out);
  }
  out["peak_memory_mb"] = peak_rss_mb();
  return out;
}

// bench: the pipeline's steps timed on the sample case
Subcommand add_bench(CLI::App& app, const bool& json) {
  auto o = std::make_shared<BenchOptions>();
  auto* cmd = app.add_subcommand("bench", "Time the pipeline's steps on the sample case");
  cmd->add_option("--input", o->input, "volume or mesh instead of the sample case");
  cmd->add_option("--runs", o->runs, "repetitions per step (median reported)")
      ->check(CLI::Range(1, 100));
  return {cmd, [o, &json] {
            print_result(run_bench(*o), json);
            return kOk;
          }};
}

}  // namespace cranioplan::cli
