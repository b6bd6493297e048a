#include "cranioplan/algorithms/planning/propose_markers.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "cranioplan/algorithms/geometry/point_index.h"
#include "cranioplan/algorithms/geometry/surface_locator.h"
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
    case PlanMethod::ShapeModel:
      return "model";
  }
  return "auto";
}

bool plan_method_from_string(const std::string& text, PlanMethod& out) {
  for (PlanMethod m :
       {PlanMethod::Auto, PlanMethod::Mirror, PlanMethod::RimOnly, PlanMethod::ShapeModel})
    if (text == to_string(m)) {
      out = m;
      return true;
    }
  return false;
}

std::string describe_method(PlanMethod method, double mirror_coverage) {
  char buf[80];
  std::snprintf(buf, sizeof(buf), "%s (mirror covers %.0f%% of the opening)",
                method == PlanMethod::Mirror       ? "mirror-guided"
                : method == PlanMethod::ShapeModel ? "shape-model-guided"
                                                   : "rim-only fitting",
                100.0 * mirror_coverage);
  return buf;
}

namespace {

// Open somewhere: more than a few boundary edges (a reader splits a non-manifold vertex or two
// of a closed surface, which leaves a handful).
bool has_boundary(const SkullMesh& mesh) {
  int count = 0;
  for (auto heh : mesh.halfedges())
    if (mesh.is_boundary(heh) && ++count > 20) return true;
  return false;
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

// A traced rim (about a millimetre between points, in order of bearing around the axis): the
// point nearest each of evenly spaced bearings, their count the rim's length over `spacing` in
// steps of kBearingSteps. Sampled by arc length, a local change of the rim (a point moved where
// it crosses bone fragments) would move every marker after it along the rim.
constexpr int kBearingSteps = 8;

std::vector<size_t> by_bearing(const DefectRegion& defect, double spacing) {
  const std::vector<Eigen::Vector3d>& rim = defect.outer_rim;
  if (rim.size() < 3) return along(rim, spacing);
  double length = 0.0;
  for (size_t i = 0; i < rim.size(); ++i) length += (rim[(i + 1) % rim.size()] - rim[i]).norm();
  const int count =
      std::max(kBearingSteps,
               kBearingSteps * static_cast<int>(std::lround(length / spacing / kBearingSteps)));
  const Eigen::Vector3d e1 = across_axis(defect.axis, defect.frame), e2 = defect.axis.cross(e1);
  std::vector<double> bearing(rim.size());
  for (size_t i = 0; i < rim.size(); ++i) {
    const Eigen::Vector3d d = rim[i] - defect.center;
    bearing[i] = std::atan2(d.dot(e2), d.dot(e1));
  }
  std::vector<size_t> picks;
  for (int k = 0; k < count; ++k) {
    const double want = -M_PI + (k + 0.5) * 2.0 * M_PI / count;
    size_t best = 0;
    for (size_t i = 1; i < rim.size(); ++i)
      if (std::abs(std::remainder(bearing[i] - want, 2.0 * M_PI)) <
          std::abs(std::remainder(bearing[best] - want, 2.0 * M_PI)))
        best = i;
    if (picks.empty() || picks.back() != best) picks.push_back(best);
  }
  return picks;
}

// Where the rays start. The vault's centre (vault_center, found from the skull's vertex
// centroid on the plane: any start in the cavity converges to it within 0.05 mm) is a property
// of the bone: meshing hardly moves it, and a crop of the face only a little (docs/AUTOPLAN.md).
// A small opening seen from it is seen narrow and its rim at a grazing angle, so the start
// moves from there towards the opening until the opening is seen 50° wide (at most half the
// vault's radius). An opening seen that wide from the vault's centre already (large cut-out
// defects) keeps the surface centroid, where those plans measure best
// (docs/decisions/0010-other-starts-from-the-vault-centre.md), unless it sees the opening less
// than half as large as the vault's centre does (the vault's centre then). The surface centroid
// too when there is no vault to fit or no opening seen from it. Not the vertex centroid: it
// follows wherever the triangles are dense, and a decimation can move it into the bone of the
// skull's base, where no ray from it crosses one table
// (docs/decisions/0017-the-rays-start-not-the-vertex-centroid.md).
Eigen::Vector3d rays_start(const SkullMesh& skull, const SurfaceLocator& bone, const Plane& plane,
                           const DetectDefectParams& params) {
  constexpr double kSeenWide = 25.0 * M_PI / 180.0;
  constexpr double kFarthest = 0.5;
  constexpr double kSeenSmaller = 2.0;
  const Eigen::Vector3d centroid = plane.project(surface_centroid(skull));
  double radius = 0.0;
  std::optional<Eigen::Vector3d> vault =
      vault_center(bone, plane, plane.project(vertex_centroid(skull)), &radius);
  // Dense pieces away from the skull (a headrest, a collar) can pull the vertices' mean out of
  // the cavity, where no vault is seen: the surface's centroid then.
  if (!vault) vault = vault_center(bone, plane, centroid, &radius);
  if (!vault) return centroid;
  DetectDefectParams from_vault = params;
  from_vault.frame = skull_frame(skull, *vault, plane.normal);
  from_vault.trace_rim_on_bone = false;  // a first look: how wide the opening is seen
  const DefectRegion seen = detect_defect(skull, bone, *vault, from_vault);
  if (seen.status != DefectRegion::Status::Found || seen.outer_rim.empty()) return centroid;
  double rim = 0.0;
  for (const Eigen::Vector3d& p : seen.outer_rim) rim += (p - *vault).norm();
  rim /= static_cast<double>(seen.outer_rim.size());
  const double half_width = std::sqrt(seen.area_mm2 / M_PI);
  const double shift = rim - half_width / std::tan(kSeenWide);
  if (shift <= 0.0) {
    // Seen wide enough from the vault's centre already: the surface centroid, unless the
    // opening is much smaller seen from there. A face, a jaw and a neck in the scan pull the
    // surface centroid down to the skull base, from where most rays through a large opening on
    // the side of the head meet the temporal bone first.
    DetectDefectParams from_centroid = from_vault;
    from_centroid.frame = skull_frame(skull, centroid, plane.normal);
    const DefectRegion low = detect_defect(skull, bone, centroid, from_centroid);
    if (low.found() && low.area_mm2 * kSeenSmaller >= seen.area_mm2) return centroid;
    return *vault;
  }
  return plane.project(*vault + std::min(shift, kFarthest * radius) * seen.axis);
}

// The widest angle between the opening's axis and its rim, seen from where the rays started, deg.
double widest_rim_deg(const DefectRegion& region) {
  double widest = 0.0;
  for (const Eigen::Vector3d& p : region.outer_rim)
    widest = std::max(widest, std::acos(std::clamp(
                                  (p - region.center).normalized().dot(region.axis), -1.0, 1.0)));
  return widest * 180.0 / M_PI;
}

constexpr double kWidestRimDeg = 60.0;
constexpr double kSeenWithinDeg = 50.0;
constexpr double kMinDepthMm = 10.0;

// `region` seen from `from` instead of its own start: each ray through the opening re-aimed at
// where it crosses the rim's mean distance from the start, the ray through each other opening
// at its point 100 mm out, the rim's points as they are.
DefectRegion seen_from(const DefectRegion& region, const Eigen::Vector3d& from) {
  DefectRegion r = region;
  double radius = 0.0;
  for (const Eigen::Vector3d& p : region.outer_rim) radius += (p - region.center).norm();
  radius /= static_cast<double>(std::max<size_t>(1, region.outer_rim.size()));
  r.center = from;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (Eigen::Vector3d& d : r.hole_directions) {
    d = (region.center + radius * d - from).normalized();
    sum += d;
  }
  if (sum.norm() > 1e-9) r.axis = sum.normalized();
  for (Eigen::Vector3d& a : r.other_axes) a = (region.center + 100.0 * a - from).normalized();
  return r;
}

// A start from which the opening's rim is seen narrowest: along the normal of the plane that
// best fits the rim, behind its centroid, as deep as the rim is seen within kSeenWithinDeg of
// that normal, but kMinDepthMm or more from the bone and in sight of the first start (in the
// cavity); none when no such point sees it narrower than from the first start.
std::optional<Eigen::Vector3d> step_back(const SurfaceLocator& bone, const DefectRegion& region) {
  Eigen::Vector3d g = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : region.outer_rim) g += p;
  g /= static_cast<double>(region.outer_rim.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& p : region.outer_rim) cov += (p - g) * (p - g).transpose();
  Eigen::Vector3d n = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors().col(0);
  if (n.dot(region.axis) < 0.0) n = -n;
  auto widest_from = [&](const Eigen::Vector3d& start) {
    double widest = 0.0;
    for (const Eigen::Vector3d& p : region.outer_rim)
      widest = std::max(widest, std::acos(std::clamp((p - start).normalized().dot(n), -1.0, 1.0)));
    return widest * 180.0 / M_PI;
  };
  std::optional<Eigen::Vector3d> best;
  double best_widest = widest_rim_deg(region) - 5.0;
  for (double depth = 10.0; depth <= 150.0; depth += 5.0) {
    const Eigen::Vector3d start = g - depth * n;
    if (bone.first_hit(region.center, start) || bone.closest(start).distance < kMinDepthMm)
      continue;
    const double widest = widest_from(start);
    if (widest < best_widest) {
      best = start;
      best_widest = widest;
    }
    if (widest <= kSeenWithinDeg) break;
  }
  return best;
}

}  // namespace

DefectRegion detect_defect_near_plane(const SkullMesh& skull, const SurfaceLocator& bone,
                                      const Plane& plane, const DetectDefectParams& params) {
  DetectDefectParams framed = params;
  if (!framed.scan_borders) {
    // A closed surface's border can only be a cap: the caps alone, not the whole report.
    MeshReport report;
    if (has_boundary(skull))
      report = report_mesh(skull);
    else
      report.caps = border_caps(skull);
    framed.scan_borders = scan_borders(report);
  }
  const Eigen::Vector3d center =
      params.center ? *params.center : rays_start(skull, bone, plane, framed);
  if (!params.frame) framed.frame = skull_frame(skull, center, plane.normal);
  DefectRegion region = detect_defect(skull, bone, center, framed);
  if (params.center || !region.found()) return region;
  // A large opening on the side of the head (a decompressive craniectomy) is seen from the
  // midline up to 80° wide: its surfaces and its shell are parametrised along rays that would
  // meet its edge nearly side-on (the shell's rays stop at 75°). The opening found is then seen
  // from further back, away from it, until its rim lies within kSeenWithinDeg of its axis (at
  // most until the start is kMinDepthMm from the bone): its rays re-aimed from there, its rim as
  // it is.
  const double widest = widest_rim_deg(region);
  if (widest <= kWidestRimDeg) return region;
  const std::optional<Eigen::Vector3d> back = step_back(bone, region);
  if (!back) return region;
  return seen_from(region, *back);
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

std::string SurfaceSources::describe() const {
  std::string parts;
  auto add = [&](double share, const char* what) {
    if (share < 0.005) return;
    char text[80];
    std::snprintf(text, sizeof text, "%s%.0f%% %s", parts.empty() ? "" : ", ", 100.0 * share, what);
    parts += text;
  };
  const double primary = mirror + ring;
  // The model is averaged in over `with_model` of the rays, either source's alike: split it in
  // proportion.
  const double model_share = primary > 0.0 ? with_model / primary : 0.0;
  add(mirror * model_share, "mirror with the shape model");
  add(mirror * (1.0 - model_share), model_share > 0.0 ? "mirror alone" : "mirror");
  add(ring * model_share, "ring fit with the shape model");
  add(ring * (1.0 - model_share), model_share > 0.0 ? "ring fit alone" : "ring fit");
  add(none, "bridged from the surfaces around (no value along those rays)");
  return "the opening's surfaces: " + (parts.empty() ? std::string("none") : parts) +
         "; edge markers on them along the rim, support markers on the skull's own bone";
}

double mirror_coverage(const DefectRegion& defect, const SurfaceLocator& mirror,
                       const ProposeParams& params) {
  size_t covered = 0;
  for (const auto& d : defect.hole_directions)
    if (cast_through_bone(mirror, defect.center, d, 400.0, 0.5, params.detect.max_thickness_mm)
            .paired)
      ++covered;
  return defect.hole_directions.empty()
             ? 0.0
             : static_cast<double>(covered) / defect.hole_directions.size();
}

namespace {

// How far from the opening the ring's bone carries support markers, mm.
double support_band_mm(const ProposeParams& params) {
  return params.surfaces.rim_clearance_mm + params.detect.support_width_mm;
}

// The fitted surfaces along each ring ray within `reach` of the opening (none further out, or
// where the fit does not reach): the edge and the support markers both judge the ring's bone
// by them, and mirror-guided each is a ray cast through the mirror.
using FittedPoints = std::optional<std::pair<Eigen::Vector3d, Eigen::Vector3d>>;
std::vector<FittedPoints> fitted_along_ring(const DefectRegion& defect,
                                            const DefectSurfaces& surfaces, double reach) {
  std::vector<FittedPoints> fitted(surfaces.ring_outer.size());
  for (size_t i = 0; i < surfaces.ring_outer.size(); ++i)
    if (surfaces.ring_distance_mm[i] <= reach)
      fitted[i] = surfaces.at((surfaces.ring_outer[i] - defect.center).normalized());
  return fitted;
}

// Outer edge markers along the rim. Where intact bone continues beyond the rim (the ring has
// bone just outside it), on the fitted outer surface: at a cut face that is not along the
// rays, the last bone the rays meet lies below where the outer table goes on. Where it does
// not (the rim runs along an orbit or the skull base), rim-only the fit only extrapolates
// there: at the last bone. Mirror-guided, the fitted surface there is the mirror's own outer
// table (where the mirror has bone), and the marker stands on it too: the rim's rays meet the
// rounded edge of the bone above an orbit at a grazing angle, and where they meet it moves by
// millimetres when the rays' start moves by a fraction of a millimetre, the brow's lower wall
// with it (docs/decisions/0012-what-moves-the-brows-lower-wall.md). No inner edge
// markers: the inner rim is the outer one set in by the thickness field of the inner markers
// (docs/IMPLANT.md).
// The ring is probed by direction from the centre, not by position (at an oblique cut face
// the rim's last bone is the cut's inner corner, a table's thickness below the ring's outer
// table), 5 and 7 mm out, with the ring's bone up to 15 mm out (the rays that leave through
// such a face are not in the ring, so it may begin several millimetres beyond the rim; further
// out the probes find bone across an orbit: docs/decisions/0004-marker-rules.md). Only ring
// bone on the fitted outer surface counts: bone met far below it is not the outer table going
// on.
constexpr double kEdgeRingReach = 12.0;  // beyond the rim clearance, mm

// Along the scan's end the rim is where the table would cross the border's plane
// (trace_rim.h), and the fitted outer surface may cross it a little further out or in. An
// edge marker there stands on the fitted surface kBeyondScanEndMm past the plane, found by
// turning the rim's direction away from the opening's axis in steps of kScanEndStepDeg (up to
// kScanEndTurnDeg): the implant is built across the scan's end and cut flat at it
// (ImplantParams::scan_ends), not ended short of it where the fit runs lower than the table's
// distance the rim was put at. None when the rim point is not on a scan's end or the fitted
// surface does not reach past it.
constexpr double kBeyondScanEndMm = 1.5, kScanEndStepDeg = 0.5, kScanEndTurnDeg = 20.0;

std::optional<Eigen::Vector3d> past_the_scans_end(const DefectRegion& defect,
                                                  const DefectSurfaces& surfaces,
                                                  const Eigen::Vector3d& rim) {
  const Plane* end = nullptr;  // the nearest within kOnScanEndMm
  for (const Plane& e : defect.scan_ends)
    if (std::abs(e.signed_distance(rim)) < kOnScanEndMm &&
        (!end || std::abs(e.signed_distance(rim)) < std::abs(end->signed_distance(rim))))
      end = &e;
  if (!end) return std::nullopt;
  const Eigen::Vector3d dir = (rim - defect.center).normalized();
  Eigen::Vector3d away = dir.dot(defect.axis) * dir - defect.axis;  // across dir, off the axis
  if (away.norm() < 1e-9) return std::nullopt;
  away.normalize();
  for (double turn = 0.0; turn <= kScanEndTurnDeg + 1e-9; turn += kScanEndStepDeg) {
    const double b = turn * M_PI / 180.0;
    const auto fitted = surfaces.at(std::cos(b) * dir + std::sin(b) * away);
    if (!fitted) return std::nullopt;
    if (end->signed_distance(fitted->first) >= kBeyondScanEndMm) return fitted->first;
  }
  return std::nullopt;
}

void add_edge_markers(const DefectRegion& defect, const DefectSurfaces& surfaces,
                      const std::vector<FittedPoints>& ring_fit, const ProposeParams& params,
                      int& id, std::vector<Marker>& out) {
  const Eigen::Vector3d c = defect.center;
  const double clearance = params.surfaces.rim_clearance_mm;
  std::vector<Eigen::Vector3d> near_ring;
  std::vector<char> on_surface;
  for (size_t i = 0; i < surfaces.ring_outer.size(); ++i)
    if (surfaces.ring_distance_mm[i] <= clearance + kEdgeRingReach) {
      const auto& fitted = ring_fit[i];
      near_ring.push_back((surfaces.ring_outer[i] - c).normalized());
      on_surface.push_back(fitted && (fitted->first - surfaces.ring_outer[i]).norm() < 1.5);
    }
  const PointIndex near_index(near_ring.empty() ? std::vector<Eigen::Vector3d>{c} : near_ring);
  auto bone_beyond = [&](const Eigen::Vector3d& rim) {
    Eigen::Vector3d outward = rim - c;
    outward -= outward.dot(defect.axis) * defect.axis;  // away from the opening's axis
    const double radius = (rim - c).norm();
    if (near_ring.empty() || outward.norm() < 1e-9 || radius < 1e-9) return false;
    for (double step = 2.0; step <= 4.0; step += 2.0) {
      const Eigen::Vector3d probe =
          (rim + (clearance + step) * outward.normalized() - c).normalized();
      int count = 0;
      for (size_t k : near_index.within_radius(probe, 4.0 / radius)) count += on_surface[k];
      if (count >= 2) return true;
    }
    return false;
  };
  // How far from the centre the rim's neighbours lie (median of four on each side), for rim
  // points where no fitted surface says where this bone is (mirror-guided, where the mirror
  // has no bone either).
  const size_t n_rim = defect.outer_rim.size();
  auto neighbours_radius = [&](size_t i) {
    std::vector<double> r;
    for (size_t k = 1; k <= 4 && k < n_rim; ++k)
      for (size_t j : {(i + k) % n_rim, (i + n_rim - k) % n_rim})
        r.push_back((defect.outer_rim[j] - c).norm());
    std::nth_element(r.begin(), r.begin() + r.size() / 2, r.end());
    return r.empty() ? 0.0 : r[r.size() / 2];
  };
  const std::vector<size_t> picks = defect.rim_traced
                                        ? by_bearing(defect, params.edge_spacing_mm)
                                        : along(defect.outer_rim, params.edge_spacing_mm);
  for (size_t i : picks) {
    const Eigen::Vector3d& rim = defect.outer_rim[i];
    if (const auto beyond = past_the_scans_end(defect, surfaces, rim)) {
      out.push_back({id++, MarkerType::OuterEdge, *beyond, MarkerSurface::Original});
      continue;
    }
    const auto fitted = surfaces.at(rim - c);
    if (fitted && (surfaces.mirror_guided || bone_beyond(rim))) {
      out.push_back({id++, MarkerType::OuterEdge, fitted->first, MarkerSurface::Original});
      continue;
    }
    // At the rim's last bone: rim-only where no intact bone continues beyond the rim, and where
    // it does but no fitted surface says where (mirror-guided, the mirror has no bone there: a
    // rim point left out there leaves the outline to cut straight across that stretch). Not
    // where that bone lies below the fitted bone altogether (rim-only), or, without a fitted
    // surface there, more than one layer of bone below its neighbours on the rim: its ray met other
    // bone past the vault's edge (an orbital roof, a sinus wall), and a marker there pulls the
    // implant's outer surface down into a funnel (docs/decisions/0004-marker-rules.md).
    const double radius = (rim - c).norm();
    if (fitted ? radius < (fitted->second - c).norm() - 1.0
               : radius < neighbours_radius(i) - params.detect.max_thickness_mm)
      continue;
    out.push_back({id++, MarkerType::OuterEdge, rim, MarkerSurface::Original});
  }
}

// Support markers: the intact bone next to the rim (the ring's nearest band). Inner ones
// where the ray's first bone is the inner table (it faces the ray), also where the ray did
// not meet both tables squarely: next to a real defect's rim the bone thins and bends, and
// the implant meets it only if its inner surface follows it (inner ones only where both
// tables are parallel leave a gap at the rim: docs/decisions/0004-marker-rules.md).
// Not where the first bone is a cut face met side-on: it lies above where the inner table
// goes on, and the implant's inner surface would rise to it and leave the wedge of bone under
// the cut empty (docs/decisions/0004-marker-rules.md).

void add_support_markers(const DefectSurfaces& surfaces, const std::vector<FittedPoints>& ring_fit,
                         const ProposeParams& params, int& id, std::vector<Marker>& out) {
  std::vector<Eigen::Vector3d> support_outer, support_inner;
  const double band = support_band_mm(params);
  const double min_facing =
      std::cos(std::clamp(params.max_support_inner_tilt_deg, 0.0, 90.0) * M_PI / 180.0) - 1e-12;
  const double max_off = params.max_support_off_fit_mm;
  // The ring's bone is one layer (ProposeParams::max_support_layers).
  std::vector<double> thickness;
  for (size_t i = 0; i < surfaces.ring_outer.size(); ++i)
    if (surfaces.ring_distance_mm[i] <= band)
      thickness.push_back((surfaces.ring_outer[i] - surfaces.ring_inner[i]).norm());
  double max_layer = std::numeric_limits<double>::infinity();
  if (!thickness.empty() && params.max_support_layers > 0.0) {
    std::nth_element(thickness.begin(), thickness.begin() + thickness.size() / 2, thickness.end());
    max_layer = params.max_support_layers * thickness[thickness.size() / 2] + 1.0;
  }
  for (size_t i = 0; i < surfaces.ring_outer.size(); ++i)
    if (surfaces.ring_distance_mm[i] <= band) {
      // A ring point the fitted surfaces do not reach (outside their cap) is kept: nothing
      // tells it from the table.
      const FittedPoints& fitted = ring_fit[i];
      const bool judged = max_off > 0.0 && fitted;
      const bool outer_on_fit =
          !judged || (fitted->first - surfaces.ring_outer[i]).norm() <= max_off;
      const bool inner_on_fit =
          !judged || (fitted->second - surfaces.ring_inner[i]).norm() <= max_off;
      if (outer_on_fit) support_outer.push_back(surfaces.ring_outer[i]);
      if (inner_on_fit && surfaces.ring_inner_facing[i] >= min_facing &&
          (surfaces.ring_outer[i] - surfaces.ring_inner[i]).norm() <= max_layer)
        support_inner.push_back(surfaces.ring_inner[i]);
    }
  for (size_t i : thin_points(support_outer, params.surface_spacing_mm))
    out.push_back({id++, MarkerType::OuterSurface, support_outer[i], MarkerSurface::Original});
  for (size_t i : thin_points(support_inner, params.surface_spacing_mm))
    out.push_back({id++, MarkerType::InnerSurface, support_inner[i], MarkerSurface::Original});
}

// Surface markers over the opening, on the fitted surfaces. The paper's smoother with the rim
// fixed evens out their spacing; each is then put back onto its fitted surface along its ray
// (the smoother alone would flatten the curvature).
void add_surface_markers(const DefectRegion& defect, const DefectSurfaces& surfaces,
                         MarkerSurface fitted_on, const ProposeParams& params, int& id,
                         std::vector<Marker>& out) {
  std::vector<Eigen::Vector3d> hole_outer, hole_inner;
  for (const auto& d : defect.hole_directions)
    if (const auto p = surfaces.at(d)) {
      hole_outer.push_back(p->first);
      hole_inner.push_back(p->second);
    }
  std::vector<Marker> inside;
  for (size_t i : thin_points(hole_outer, params.surface_spacing_mm))
    inside.push_back({id++, MarkerType::OuterSurface, hole_outer[i], fitted_on});
  for (size_t i : thin_points(hole_inner, params.surface_spacing_mm))
    inside.push_back({id++, MarkerType::InnerSurface, hole_inner[i], fitted_on});
  std::vector<Marker> to_smooth;
  for (const auto& m : out)
    if (is_edge(m.type)) to_smooth.push_back(m);
  to_smooth.insert(to_smooth.end(), inside.begin(), inside.end());
  for (Marker m : smooth_markers(to_smooth, params.smooth, nullptr).markers) {
    if (is_edge(m.type)) continue;
    const auto p = surfaces.at(m.position - defect.center);
    if (!p) continue;
    m.position = is_outer(m.type) ? p->first : p->second;
    out.push_back(m);
  }
}

// Which sources give the surfaces along the opening's rays.
SurfaceSources sources_of(const DefectRegion& defect, const DefectSurfaces& surfaces) {
  SurfaceSources s;
  if (defect.hole_directions.empty()) return s;
  size_t primary = 0, none = 0;
  double blended = 0.0;
  for (const auto& d : defect.hole_directions) {
    if (!surfaces.at(d)) {
      ++none;
      continue;
    }
    ++primary;
    blended += surfaces.blend_share(d);
  }
  const double n = static_cast<double>(defect.hole_directions.size());
  (surfaces.mirror_guided ? s.mirror : s.ring) = primary / n;
  s.with_model = blended / n;
  s.none = none / n;
  return s;
}

}  // namespace

MarkerProposal propose_markers_for_defect(const DefectRegion& defect, const SurfaceLocator& bone,
                                          const SurfaceLocator& mirror, const ProposeParams& params,
                                          int first_id, const SurfaceLocator* model) {
  MarkerProposal r;
  r.defect = defect;
  if (!defect.found()) {
    r.message = defect.message;
    return r;
  }
  r.mirror_coverage = mirror_coverage(defect, mirror, params);
  const bool mirror_covers = r.mirror_coverage >= params.min_mirror_coverage;
  // Auto: the mirror where it covers the opening; elsewhere the shape model when one fits,
  // else the ring.
  r.method_used = params.method == PlanMethod::Auto ? (mirror_covers ? PlanMethod::Mirror
                                                       : model       ? PlanMethod::ShapeModel
                                                                     : PlanMethod::RimOnly)
                                                    : params.method;
  if (r.method_used == PlanMethod::ShapeModel && !model) {
    r.status = MarkerProposal::Status::Failed;
    r.message = defect.message + "; the shape model was asked for, and none fits this skull";
    return r;
  }
  const bool guided = r.method_used == PlanMethod::Mirror ||
                      (r.method_used == PlanMethod::ShapeModel && mirror_covers);
  DefectSurfaces surfaces =
      fit_defect_surfaces(defect, bone, guided ? &mirror : nullptr, params.surfaces, params.detect);
  if (r.method_used == PlanMethod::ShapeModel && surfaces.fitted()) {
    // The mirror's or the ring's surfaces with the shape model's averaged in where the model
    // reaches (its template may stop short of an opening's lower edge).
    auto shaped = std::make_shared<DefectSurfaces>(
        fit_defect_surfaces(defect, bone, model, params.surfaces, params.detect));
    // The taper looks for where the model stops among the opening's rays and the rim's (the
    // edge markers stand on these surfaces along the rim).
    std::vector<Eigen::Vector3d> directions = defect.hole_directions;
    for (const auto& p : defect.outer_rim) directions.push_back((p - defect.center).normalized());
    surfaces.blend_with(shaped, params.shape_model_weight, directions);
  }
  r.surfaces_message = surfaces.message;
  if (!surfaces.fitted()) {
    r.status = MarkerProposal::Status::Failed;
    r.message = defect.message + "; " + surfaces.message;
    return r;
  }
  r.ring_rms_mm = surfaces.outer_rms_mm;
  r.sources = sources_of(defect, surfaces);
  r.surfaces_message += "; " + r.sources.describe();
  int id = first_id;
  const std::vector<FittedPoints> ring_fit = fitted_along_ring(
      defect, surfaces,
      std::max(params.surfaces.rim_clearance_mm + kEdgeRingReach, support_band_mm(params)));
  add_edge_markers(defect, surfaces, ring_fit, params, id, r.markers);
  add_support_markers(surfaces, ring_fit, params, id, r.markers);
  add_surface_markers(defect, surfaces, guided ? MarkerSurface::Mirrored : MarkerSurface::Original,
                      params, id, r.markers);
  r.status = MarkerProposal::Status::Proposed;
  r.message = defect.message;
  return r;
}

MarkerProposal propose_markers(const SkullMesh& skull, const SurfaceLocator& bone,
                               const Plane& plane, const SurfaceLocator& mirror,
                               const ProposeParams& params, int first_id) {
  return propose_markers_for_defect(detect_defect_near_plane(skull, bone, plane, params.detect),
                                    bone, mirror, params, first_id);
}

}  // namespace cranioplan
