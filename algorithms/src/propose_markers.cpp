#include "cranioplan/algorithms/propose_markers.h"

#include "cranioplan/algorithms/surface_locator.h"
#include "cranioplan/model/mesh.h"

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

bool plan_method_from_string(const std::string& text, PlanMethod& out) {
  for (PlanMethod m : {PlanMethod::Auto, PlanMethod::Mirror, PlanMethod::RimOnly})
    if (text == to_string(m)) {
      out = m;
      return true;
    }
  return false;
}

namespace {

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

DefectRegion detect_defect_near_plane(const SkullMesh& skull, const SurfaceLocator& bone,
                                      const Plane& plane, const DetectDefectParams& params) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (auto vh : skull.vertices()) centroid += to_eigen(skull.point(vh));
  centroid /= static_cast<double>(std::max<size_t>(1, skull.n_vertices()));
  return detect_defect(skull, bone, plane.project(centroid), params);
}

RegionOfInterest local_registration_region(const DefectRegion& defect, double margin_mm) {
  RegionOfInterest roi;
  roi.shape = RegionOfInterest::Shape::Sphere;
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& p : defect.outer_rim) c += p;
  if (!defect.outer_rim.empty()) c /= static_cast<double>(defect.outer_rim.size());
  double r = 0.0;
  for (const auto& p : defect.outer_rim) r = std::max(r, (p - c).norm());
  roi.center = c;
  roi.radius = r + margin_mm;
  return roi;
}

MarkerProposal propose_markers_for_defect(const DefectRegion& defect, const SurfaceLocator& mirror,
                                          const ProposeParams& params, int first_id) {
  MarkerProposal r;
  r.defect = defect;
  if (!defect.found()) {
    r.message = defect.message;
    return r;
  }
  // Mirror coverage: rays through the opening that meet the mirrored bone (both tables).
  std::vector<Eigen::Vector3d> mirror_outer, mirror_inner;
  const Eigen::Vector3d c = defect.center;
  for (const auto& d : defect.hole_directions) {
    const auto in = mirror.first_hit(c, c + 400.0 * d);
    const auto out = mirror.first_hit(c + 400.0 * d, c);
    const double gap = in && out ? (out->point - in->point).norm() : 0.0;
    if (gap > 0.5 && gap <= params.detect.max_thickness_mm) {
      mirror_inner.push_back(in->point);
      mirror_outer.push_back(out->point);
    }
  }
  r.mirror_coverage = defect.hole_directions.empty() ? 0.0
                                                     : static_cast<double>(mirror_outer.size()) /
                                                           defect.hole_directions.size();
  r.method_used = params.method == PlanMethod::Auto
                      ? (r.mirror_coverage >= params.min_mirror_coverage ? PlanMethod::Mirror
                                                                         : PlanMethod::RimOnly)
                      : params.method;

  // Proposed markers: edges along both rims, support from the intact ring, surface markers
  // from the mirror.
  int id = first_id;
  // Outer edge markers only: at a cut face that is not along the rays, the inner table's end
  // cannot be told from the rays that found the rim (they graze the cut); the inner rim is the
  // outer one set in by the thickness the inner markers measure.
  for (size_t i : along(defect.outer_rim, params.edge_spacing_mm))
    r.markers.push_back(
        {id++, MarkerType::OuterEdge, defect.outer_rim[i], MarkerSurface::Original});
  for (size_t i : thin_out(defect.outer_support, params.surface_spacing_mm))
    r.markers.push_back(
        {id++, MarkerType::OuterSurface, defect.outer_support[i], MarkerSurface::Original});
  for (size_t i : thin_out(defect.inner_support, params.surface_spacing_mm))
    r.markers.push_back(
        {id++, MarkerType::InnerSurface, defect.inner_support[i], MarkerSurface::Original});
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
  r.status = MarkerProposal::Status::Proposed;
  r.message = defect.message;
  return r;
}

MarkerProposal propose_markers(const SkullMesh& skull, const SurfaceLocator& bone,
                               const Plane& plane, const SurfaceLocator& mirror,
                               const ProposeParams& params, int first_id) {
  return propose_markers_for_defect(detect_defect_near_plane(skull, bone, plane, params.detect),
                                    mirror, params, first_id);
}

}  // namespace cranioplan
