#include "cranioplan/algorithms/autoplan.h"

#include <chrono>
#include <cstdio>

#include "cranioplan/algorithms/mirror_mesh.h"
#include "cranioplan/algorithms/surface_locator.h"

namespace cranioplan {

const char* to_string(PlanMethod m) {
  switch (m) {
    case PlanMethod::Auto:
      return "auto";
    case PlanMethod::Mirror:
      return "mirror";
    case PlanMethod::RimOnly:
      return "rim-only";
  }
  return "auto";
}

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

// Points at least `spacing` apart, greedily in the given order.
std::vector<size_t> thin_out(const std::vector<Eigen::Vector3d>& pts, double spacing) {
  std::vector<size_t> kept;
  for (size_t i = 0; i < pts.size(); ++i) {
    bool far = true;
    for (size_t k : kept)
      if ((pts[k] - pts[i]).squaredNorm() < spacing * spacing) {
        far = false;
        break;
      }
    if (far) kept.push_back(i);
  }
  return kept;
}

// Along an ordered closed polyline, indices every `spacing` mm of arc length.
std::vector<size_t> along(const std::vector<Eigen::Vector3d>& loop, double spacing) {
  std::vector<size_t> out;
  double run = spacing;
  for (size_t i = 0; i < loop.size(); ++i) {
    if (i > 0) run += (loop[i] - loop[i - 1]).norm();
    if (run >= spacing) {
      out.push_back(i);
      run = 0.0;
    }
  }
  return out;
}

}  // namespace

AutoplanResult autoplan(const SkullMesh& skull, const Landmarks& landmarks,
                        const AutoplanParams& params) {
  AutoplanResult r;
  StageTimer timer(r.stage_seconds);
  r.plane = fit_sagittal_plane(skull, landmarks, params.plane);
  timer.stage("plane");
  if (!r.plane.usable()) {
    r.message = "midsagittal plane: " + r.plane.message;
    return r;
  }
  const SkullMesh mirrored = mirror_mesh(skull, r.plane.plane);
  timer.stage("mirror");
  r.registration = register_icp(mirrored, skull, params.registration);
  r.mirrored =
      r.registration.usable() ? transform_mesh(mirrored, r.registration.transform) : mirrored;
  timer.stage("register");

  const SurfaceLocator bone(skull);
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (auto vh : skull.vertices()) centroid += to_eigen(skull.point(vh));
  centroid /= static_cast<double>(std::max<size_t>(1, skull.n_vertices()));
  r.defect = detect_defect(skull, bone, r.plane.plane.project(centroid), params.detect);
  timer.stage("detect");
  if (!r.defect.found()) {
    r.status = AutoplanResult::Status::NoDefect;
    r.message = r.defect.message;
    return r;
  }

  // Mirror coverage: rays through the opening that meet the mirrored bone (both tables).
  const SurfaceLocator mirror(r.mirrored);
  std::vector<Eigen::Vector3d> mirror_outer, mirror_inner;
  const Eigen::Vector3d c = r.defect.center;
  for (const auto& d : r.defect.hole_directions) {
    const auto in = mirror.first_hit(c, c + 400.0 * d);
    const auto out = mirror.first_hit(c + 400.0 * d, c);
    const double gap = in && out ? (out->point - in->point).norm() : 0.0;
    if (gap > 0.5 && gap <= params.detect.max_thickness_mm) {
      mirror_inner.push_back(in->point);
      mirror_outer.push_back(out->point);
    }
  }
  r.mirror_coverage = r.defect.hole_directions.empty() ? 0.0
                                                       : static_cast<double>(mirror_outer.size()) /
                                                             r.defect.hole_directions.size();
  r.method_used = params.method == PlanMethod::Auto
                      ? (r.mirror_coverage >= params.min_mirror_coverage ? PlanMethod::Mirror
                                                                         : PlanMethod::RimOnly)
                      : params.method;

  // Proposed markers: edges along both rims, support from the intact ring, surface markers
  // from the mirror.
  int id = 1;
  // Outer edge markers only: at a cut face that is not along the rays, the inner table's end
  // cannot be told from the rays that found the rim (they graze the cut); the inner rim is the
  // outer one set in by the thickness the inner markers measure.
  for (size_t i : along(r.defect.outer_rim, params.edge_spacing_mm))
    r.markers.push_back(
        {id++, MarkerType::OuterEdge, r.defect.outer_rim[i], MarkerSurface::Original});
  for (size_t i : thin_out(r.defect.outer_support, params.surface_spacing_mm))
    r.markers.push_back(
        {id++, MarkerType::OuterSurface, r.defect.outer_support[i], MarkerSurface::Original});
  for (size_t i : thin_out(r.defect.inner_support, params.surface_spacing_mm))
    r.markers.push_back(
        {id++, MarkerType::InnerSurface, r.defect.inner_support[i], MarkerSurface::Original});
  if (r.method_used == PlanMethod::Mirror) {
    std::vector<Marker> mirror_markers;
    for (size_t i : thin_out(mirror_outer, params.surface_spacing_mm))
      mirror_markers.push_back(
          {id++, MarkerType::OuterSurface, mirror_outer[i], MarkerSurface::Mirrored});
    for (size_t i : thin_out(mirror_inner, params.surface_spacing_mm))
      mirror_markers.push_back(
          {id++, MarkerType::InnerSurface, mirror_inner[i], MarkerSurface::Mirrored});
    // The paper's smoother on the mirror's markers with the rim fixed, back onto the mirror.
    std::vector<Marker> to_smooth;
    for (const auto& m : r.markers)
      if (is_edge(m.type)) to_smooth.push_back(m);
    to_smooth.insert(to_smooth.end(), mirror_markers.begin(), mirror_markers.end());
    const SmoothResult s = smooth_markers(to_smooth, params.smooth, &mirror);
    for (const auto& m : s.markers)
      if (m.surface == MarkerSurface::Mirrored) r.markers.push_back(m);
  }
  timer.stage("markers");

  ImplantParams implant = params.implant;
  implant.radial_center = r.defect.center;  // the rays that found the opening
  r.implant = build_implant(r.markers, &skull, &bone, implant);
  timer.stage("implant");
  if (!r.implant.usable()) {
    r.message = "implant: " + r.implant.message;
    return r;
  }
  r.quality = check_implant(r.implant.mesh, &skull);
  timer.stage("quality");
  r.status = AutoplanResult::Status::Planned;
  char buf[200];
  std::snprintf(buf, sizeof(buf), "%s; %s (mirror covers %.0f%% of the opening)",
                r.defect.message.c_str(),
                r.method_used == PlanMethod::Mirror ? "mirror-guided" : "rim-only fitting",
                100.0 * r.mirror_coverage);
  r.message = buf;
  return r;
}

}  // namespace cranioplan
