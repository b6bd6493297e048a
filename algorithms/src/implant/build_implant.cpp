#include "cranioplan/algorithms/implant/build_implant.h"

#include <vtkCellArray.h>
#include <vtkDataSetSurfaceFilter.h>
#include <vtkDelaunay3D.h>
#include <vtkIdList.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkTriangleFilter.h>
#include <vtkUnstructuredGrid.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>

#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/geometry/thin_plate_spline.h"
#include "cranioplan/algorithms/implant/rim_gap.h"
#include "cranioplan/algorithms/implant/trim_to_bone.h"
#include "cranioplan/algorithms/io/mesh_report.h"
#include "cranioplan/model/error.h"
#include "cranioplan/model/parallel.h"
#include "cranioplan/model/plane.h"
#include "stage_clock.h"

namespace cranioplan {

const char* status_name(ImplantResult::Status status) {
  switch (status) {
    case ImplantResult::Status::Built:
      return "built";
    case ImplantResult::Status::TooFewMarkers:
      return "too_few_markers";
    case ImplantResult::Status::Failed:
      break;
  }
  return "failed";
}

const char* to_string(ImplantMethod m) {
  return m == ImplantMethod::Shell ? "shell" : "delaunay3d";
}

namespace {

constexpr double kTwoPi = 2.0 * M_PI;
// Markers closer than this (mm, in the parametrisation) to an earlier one are not fitted.
constexpr double kMinMarkerSeparation = 1.0;
// More clearance zones than a rim has stretches (each voxel of the fit weighs every zone).
constexpr size_t kMaxClearanceZones = 100;
// A plate laid on the bone follows the bone's outer surface up to this far above the fitted one.
constexpr double kOnlaySearchMm = 20.0;
// Fitting to the bone seeks the bone to meet up to this many times the margin beyond the rim.
constexpr double kFitReach = 3.0;
// ImplantParams::fit_margin_search: the margins tried after the one asked, in this order, as
// steps from it (mm), and the range they are kept in.
constexpr double kFitMarginSteps[] = {1.0, -1.0, 2.0, -2.0};
constexpr double kMinSearchedMarginMm = 1.0, kMaxSearchedMarginMm = 10.0;

// The parametrisation of the defect's surfaces as height fields h(u, v).
// Planar: (u, v) in the plane of the outer markers, h along its normal n.
// Radial: rays from a centre inside the skull; (u, v) is the gnomonic projection of the ray
// around the axis n (scaled to mm at the markers' radius), h the distance from the centre.
// Radial handles large, strongly curved defects: rays from inside never cross.
struct Frame {
  bool radial = false;
  Eigen::Vector3d origin, e1, e2, n;
  double scale = 1.0;
  Eigen::Vector2d uv(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d d = p - origin;
    if (!radial) return {d.dot(e1), d.dot(e2)};
    const double t = std::max(d.dot(n), 1e-3 * d.norm());
    return Eigen::Vector2d(d.dot(e1), d.dot(e2)) * (scale / t);
  }
  double h(const Eigen::Vector3d& p) const {
    return radial ? (p - origin).norm() : (p - origin).dot(n);
  }
  Eigen::Vector3d up(const Eigen::Vector2d& q) const {
    return radial ? Eigen::Vector3d((n + (q.x() / scale) * e1 + (q.y() / scale) * e2).normalized())
                  : n;
  }
  Eigen::Vector3d lift(const Eigen::Vector2d& q, double height) const {
    if (radial) return origin + height * up(q);
    return origin + q.x() * e1 + q.y() * e2 + height * n;
  }
};

// A point of a ring: its position in the plane, its polar angle (unwrapped) and its vertex.
struct RingPoint {
  double angle;
  int vertex;
};
using Ring = std::vector<RingPoint>;

// A closed polygon in polar form around a centre: points sorted by angle.
struct PolarPolygon {
  Eigen::Vector2d center;
  std::vector<double> angle;           // ascending in [-π, π)
  std::vector<Eigen::Vector2d> point;  // same order
  std::vector<double> extra;           // a value carried along (height correction)

  static double angle_of(const Eigen::Vector2d& c, const Eigen::Vector2d& p) {
    return std::atan2(p.y() - c.y(), p.x() - c.x());
  }
  void sort() {
    std::vector<size_t> order(angle.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return angle[a] < angle[b]; });
    PolarPolygon s{center, {}, {}, {}};
    for (size_t i : order) {
      s.angle.push_back(angle[i]);
      s.point.push_back(point[i]);
      s.extra.push_back(extra.empty() ? 0.0 : extra[i]);
    }
    *this = s;
  }
  // Where the ray from the centre at angle `a` crosses the polygon, and the carried value
  // interpolated there.
  std::pair<Eigen::Vector2d, double> at(double a) const {
    const size_t n = angle.size();
    a = std::remainder(a, kTwoPi);
    size_t hi = std::upper_bound(angle.begin(), angle.end(), a) - angle.begin();
    const size_t i0 = (hi + n - 1) % n, i1 = hi % n;
    const Eigen::Vector2d p0 = point[i0], p1 = point[i1];
    const Eigen::Vector2d dir(std::cos(a), std::sin(a));
    // center + t·dir = p0 + s·(p1 − p0)
    Eigen::Matrix2d M;
    M.col(0) = dir;
    M.col(1) = p0 - p1;
    const Eigen::Vector2d rhs = p0 - center;
    double s = 0.0;
    if (std::abs(M.determinant()) > 1e-12) s = std::clamp(M.inverse().row(1).dot(rhs), 0.0, 1.0);
    return {p0 + s * (p1 - p0), extra[i0] + s * (extra[i1] - extra[i0])};
  }
};

// Triangles between two closed rings sorted by angle (unwrapped from a common start), `a`
// inside `b`; counter-clockwise like the rings.
void zipper(const Ring& a, const Ring& b, std::vector<Eigen::Vector3i>& tris) {
  const size_t na = a.size(), nb = b.size();
  size_t i = 0, j = 0;
  auto ang = [](const Ring& r, size_t k) {
    return k < r.size() ? r[k].angle : r[0].angle + kTwoPi;
  };
  while (i < na || j < nb) {
    if (j >= nb || (i < na && ang(a, i + 1) <= ang(b, j + 1))) {
      tris.emplace_back(a[i % na].vertex, b[j % nb].vertex, a[(i + 1) % na].vertex);
      ++i;
    } else {
      tris.emplace_back(a[i % na].vertex, b[j % nb].vertex, b[(j + 1) % nb].vertex);
      ++j;
    }
  }
}

// A ring from polar angles. Interior rings are sorted by angle; the rim keeps its own order
// (the side wall follows it), with its angles made non-decreasing so the zipper can walk it.
Ring make_ring(const std::vector<double>& angles, int first_vertex, double start, bool keep_order) {
  Ring r;
  for (size_t k = 0; k < angles.size(); ++k) {
    double a = angles[k];
    while (a < start) a += kTwoPi;
    while (a >= start + kTwoPi) a -= kTwoPi;
    if (keep_order && !r.empty()) a = std::max(a, r.back().angle);
    r.push_back({a, first_vertex + static_cast<int>(k)});
  }
  if (!keep_order)
    std::stable_sort(r.begin(), r.end(),
                     [](const RingPoint& x, const RingPoint& y) { return x.angle < y.angle; });
  return r;
}

// Bone thickness around the defect: a few millimetres outside each outer edge marker (away
// from the defect's centre, on the intact outer table), along the inward surface normal to the
// inner table. The median, clamped to 1.5–15 mm.
double measure_bone_thickness(const std::vector<Eigen::Vector3d>& edge_points,
                              const Eigen::Vector3d& defect_center, const SurfaceLocator& skull) {
  std::vector<double> t;
  for (const auto& p : edge_points) {
    const Eigen::Vector3d away = (p - defect_center).normalized();
    const auto c = skull.closest(p + 5.0 * away);
    const Eigen::Vector3d n = skull.face_normal(c.face);
    const auto hit = skull.first_hit(c.point - 0.05 * n, c.point - 25.0 * n);
    if (hit) t.push_back(hit->distance + 0.05);
  }
  if (t.empty()) return 6.0;
  std::nth_element(t.begin(), t.begin() + t.size() / 2, t.end());
  return std::clamp(t[t.size() / 2], 1.5, 15.0);
}

using Height = std::function<double(const Eigen::Vector2d&)>;

// The shell's construction, stage by stage (build_shell runs them in order). Each stage that
// can fail says so in `result` and returns false.
class ShellBuilder {
 public:
  ShellBuilder(const std::vector<Marker>& markers, const SkullMesh* skull,
               const SurfaceLocator* skull_locator, const ImplantParams& params,
               ImplantResult& result, SkullMesh& mesh)
      : markers_(markers),
        skull_(skull),
        skull_locator_(skull_locator),
        params_(params),
        result_(result),
        mesh_(mesh) {}

  // Edge markers first: where a surface marker lies next to an edge marker, the edge wins. The
  // skull's locator (made here when none is given).
  bool gather_markers() {
    for (const auto& m : markers_) {
      if (m.type == MarkerType::OuterEdge) outer_edges_.push_back(m.position);
      if (m.type == MarkerType::InnerEdge) inner_edges_.push_back(m.position);
    }
    outer_ = outer_edges_;
    inner_ = inner_edges_;
    for (const auto& m : markers_)
      if (!is_edge(m.type)) (is_outer(m.type) ? outer_ : inner_).push_back(m.position);
    if (outer_edges_.size() < 3) {
      result_.status = ImplantResult::Status::TooFewMarkers;
      result_.message = "the shell needs at least 3 outer edge markers (" +
                        std::to_string(outer_edges_.size()) + " given)";
      return false;
    }
    has_inner_ = inner_edges_.size() >= 3;
    if (!skull_locator_ && skull_ && skull_->n_faces() > 0)
      own_locator_ = std::make_unique<SurfaceLocator>(*skull_);
    bone_ = skull_locator_ ? skull_locator_ : own_locator_.get();
    return true;
  }

  // The frame the surfaces are height fields in: rays from the centre (radial) or the plane of
  // the outer markers, normal pointing away from the skull's centre.
  void set_frame() {
    marker_centroid_ = Eigen::Vector3d::Zero();
    for (const auto& p : outer_) marker_centroid_ += p;
    marker_centroid_ /= static_cast<double>(outer_.size());
    Eigen::Vector3d skull_centre = marker_centroid_;
    if (skull_ && skull_->n_vertices() > 0) {
      skull_centre.setZero();
      for (auto vh : skull_->vertices()) skull_centre += to_eigen(skull_->point(vh));
      skull_centre /= static_cast<double>(skull_->n_vertices());
    }
    if (params_.radial_center ||
        (skull_ && skull_->n_vertices() > 0 && params_.frame == ImplantFrame::Radial)) {
      f_.radial = true;
      f_.origin = params_.radial_center ? *params_.radial_center : skull_centre;
      Eigen::Vector3d axis = Eigen::Vector3d::Zero();
      f_.scale = 0.0;
      for (const auto& p : outer_edges_) {
        axis += (p - f_.origin).normalized();
        f_.scale += (p - f_.origin).norm();
      }
      f_.n = axis.normalized();
      f_.scale /= static_cast<double>(outer_edges_.size());
      // Across the axis towards the first edge marker: the same on the skull in any pose.
      f_.e1 = unit_across(outer_edges_.front() - f_.origin, f_.n);
      f_.e2 = f_.n.cross(f_.e1);
    } else {
      f_.origin = marker_centroid_;
      Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
      for (const auto& p : outer_) cov += (p - f_.origin) * (p - f_.origin).transpose();
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
      f_.n = eig.eigenvectors().col(0);
      if (f_.n.dot(f_.origin - skull_centre) < 0) f_.n = -f_.n;
      f_.e1 = eig.eigenvectors().col(2);
      f_.e2 = f_.n.cross(f_.e1);
    }
  }

  // Rays from the centre parametrise a cap, not more: a marker far off the axis (e.g. one
  // placed on the far wall of the skull through the opening) would stretch the height field
  // without bound.
  bool markers_within_cap() {
    if (!f_.radial) return true;
    for (const auto& m : markers_) {
      const Eigen::Vector3d d = m.position - f_.origin;
      if (d.dot(f_.n) < std::cos(75.0 * M_PI / 180.0) * d.norm()) {
        result_.status = ImplantResult::Status::Failed;
        result_.message = "marker " + std::to_string(m.id) +
                          " lies more than 75° from the defect's axis, seen from inside the skull: "
                          "it is probably on the far side of the skull (placed through the "
                          "opening?) — move or delete it";
        return false;
      }
    }
    return true;
  }

  // The outer surface: a spline of heights through the outer markers. The inner surface: the
  // outer one less a thickness field, a spline through the inner markers' depths below the
  // outer surface. Thickness varies slowly, so its spline stays calm across the opening where
  // a spline of the inner heights themselves, pulled by noisy samples at the rim, can buckle.
  // Without an inner rim, inner surface markers (six or more) still give the thickness field;
  // the inner rim is then the outer one offset by it. Else the thickness is the one given, or
  // the bone's measured at the rim.
  bool fit_surfaces() {
    thickness_tps_.set_quadratic_trend(false);
    if (!fit(outer_, outer_edges_.size(), outer_tps_, nullptr)) {
      result_.message = "the outer markers lie on a line: no surface can be fitted";
      return false;
    }
    if (has_inner_ && !fit(inner_, inner_edges_.size(), thickness_tps_, &outer_tps_)) {
      result_.message = "the inner markers lie on a line: no surface can be fitted";
      return false;
    }
    thickness_from_markers_ = !has_inner_ && inner_.size() >= 6 &&
                              std::isnan(params_.thickness_mm) &&
                              fit(inner_, 0, thickness_tps_, &outer_tps_);
    result_.thickness_used_mm =
        has_inner_                ? 0.0
        : thickness_from_markers_ ? depth(Eigen::Vector2d::Zero())
        : !std::isnan(params_.thickness_mm)
            ? params_.thickness_mm
            : (bone_ ? measure_bone_thickness(outer_edges_, marker_centroid_, *bone_) : 6.0);
    return true;
  }

  // Rim polygons around the polar centre (the ray axis, radial; else the rim's centroid), and
  // the rim's sample angles: every edge marker's, densified to the resolution along the rim.
  bool rim_angles() {
    center_ = Eigen::Vector2d::Zero();
    if (!f_.radial) {
      for (const auto& p : outer_edges_) center_ += f_.uv(p);
      center_ /= static_cast<double>(outer_edges_.size());
    }
    outer_poly_ = polygon(outer_edges_);
    inner_poly_ = has_inner_ ? polygon(inner_edges_) : outer_poly_;
    res_ = std::clamp(params_.resolution_mm, 0.2, 10.0);
    std::vector<double> marker_angles = outer_poly_.angle;
    if (has_inner_)
      marker_angles.insert(marker_angles.end(), inner_poly_.angle.begin(), inner_poly_.angle.end());
    std::sort(marker_angles.begin(), marker_angles.end());
    marker_angles.erase(std::unique(marker_angles.begin(), marker_angles.end(),
                                    [](double a, double b) { return std::abs(a - b) < 1e-9; }),
                        marker_angles.end());
    auto span = [&](size_t k) {
      const double a0 = marker_angles[k];
      const double a1 =
          k + 1 < marker_angles.size() ? marker_angles[k + 1] : marker_angles[0] + kTwoPi;
      return std::make_pair(a0, a1);
    };
    auto length = [&](double a0, double a1) {
      return std::max((outer_poly_.at(a1).first - outer_poly_.at(a0).first).norm(),
                      (inner_poly_.at(a1).first - inner_poly_.at(a0).first).norm());
    };
    double rim_length = 0.0;
    for (size_t k = 0; k < marker_angles.size(); ++k) {
      const auto [a0, a1] = span(k);
      rim_length += length(a0, a1);
    }
    if (rim_length / res_ > 1e5) {
      result_.status = ImplantResult::Status::Failed;
      result_.message = "the rim through the edge markers is " +
                        format_count(std::lround(rim_length)) +
                        " mm long: the markers span too large a region (check markers far from "
                        "the defect)";
      return false;
    }
    for (size_t k = 0; k < marker_angles.size(); ++k) {
      const auto [a0, a1] = span(k);
      const int steps = std::max(1, static_cast<int>(std::ceil(length(a0, a1) / res_)));
      for (int s = 0; s < steps; ++s) {
        angles_.push_back(a0 + (a1 - a0) * s / steps);
        is_marker_angle_.push_back(s == 0);
      }
    }
    result_.rim_points = static_cast<int>(angles_.size());
    return true;
  }

  // Both rims in 3D, snapped onto the bone between markers. Where both meet the same bone point
  // the side wall would have no height: at least 0.3 mm between them, inwards along the outer
  // surface's normal.
  void rims() {
    outer_rim_ = rim_points(outer_poly_, &outer_height_);
    inner_rim_ = rim_points(inner_poly_, has_inner_ ? &inner_height_ : nullptr);
    for (size_t k = 0; k < angles_.size(); ++k)
      if ((inner_rim_[k] - outer_rim_[k]).norm() < 0.3)
        inner_rim_[k] = outer_rim_[k] - 0.3 * outer_normal(f_.uv(outer_rim_[k]));
  }

  // The number of rings from the rim to the centre, refused when the shell would be too large.
  bool ring_count() {
    double radius = 0.0;
    for (const auto& p : outer_rim_) radius = std::max(radius, (f_.uv(p) - center_).norm());
    n_rings_ = std::max(2, static_cast<int>(std::ceil(radius / res_)));
    start_ = angles_.front() - 1e-6;
    const double vertices = 2.0 * n_rings_ * static_cast<double>(angles_.size());
    if (vertices > 4e6) {
      result_.status = ImplantResult::Status::Failed;
      char buf[200];
      std::snprintf(buf, sizeof(buf),
                    "the shell would need %.0f million vertices at %.2f mm: the markers span "
                    "too large a region (check markers far from the defect)",
                    vertices / 1e6, res_);
      result_.message = buf;
      return false;
    }
    return true;
  }

  // Both caps, facing out, and the side wall between them: one closed solid.
  void assemble() {
    auto [outer_tris, outer_rim_first] = build_cap(outer_rim_, &outer_height_, false);
    auto [inner_tris, inner_rim_first] =
        build_cap(inner_rim_, has_inner_ ? &inner_height_ : nullptr, !has_inner_);
    soup_.triangles = outer_tris;
    for (auto t : inner_tris) soup_.triangles.emplace_back(t[0], t[2], t[1]);  // facing inwards
    // Side wall between rim k of both surfaces. The outer cap runs its rim o_k → o_k+1 and the
    // inner cap (facing inwards) i_k+1 → i_k, so the wall takes the opposite directions.
    const size_t n_rim = angles_.size();
    for (size_t k = 0; k < n_rim; ++k) {
      const int o0 = outer_rim_first + static_cast<int>(k);
      const int o1 = outer_rim_first + static_cast<int>((k + 1) % n_rim);
      const int i0 = inner_rim_first + static_cast<int>(k);
      const int i1 = inner_rim_first + static_cast<int>((k + 1) % n_rim);
      soup_.triangles.emplace_back(o1, o0, i0);
      soup_.triangles.emplace_back(o1, i0, i1);
    }
    if (signed_volume(soup_) < 0)  // inner surface above the outer one: markers swapped
      for (auto& t : soup_.triangles) std::swap(t[1], t[2]);
    build_mesh(soup_, mesh_);
  }

  // How far the rims pass from their edge markers, and the verdict.
  void finish() {
    for (const auto& m : markers_) {
      if (!is_edge(m.type)) continue;
      const std::vector<Eigen::Vector3d>& rim =
          m.type == MarkerType::OuterEdge ? outer_rim_ : inner_rim_;
      double best = std::numeric_limits<double>::infinity();
      for (const auto& p : rim) best = std::min(best, (p - m.position).norm());
      if (m.type == MarkerType::OuterEdge || has_inner_)
        result_.rim_marker_error_mm = std::max(result_.rim_marker_error_mm, best);
    }
    result_.watertight = is_watertight(mesh_);
    result_.status = ImplantResult::Status::Built;
    result_.message = has_inner_
                          ? "shell through outer and inner markers"
                          : "shell through outer markers, inner surface offset by the thickness";
  }

 private:
  bool fit(const std::vector<Eigen::Vector3d>& pts, size_t edges, ThinPlateSpline& tps,
           const ThinPlateSpline* below) const {
    std::vector<Eigen::Vector2d> uv;
    std::vector<double> h;
    for (const auto& p : pts) {
      uv.push_back(f_.uv(p));
      h.push_back(below ? (*below)(f_.uv(p)) - f_.h(p) : f_.h(p));
    }
    std::vector<double> smoothing(uv.size(), 0.0);
    for (size_t i = edges; i < smoothing.size(); ++i) smoothing[i] = params_.surface_smoothing;
    return tps.fit(uv, h, smoothing, kMinMarkerSeparation, edges);
  }
  // Depths are kept between 0.3 mm and 20 mm: the inner surface never crosses the outer one.
  double depth(const Eigen::Vector2d& q) const {
    return std::clamp(thickness_tps_(q), min_depth(), std::max(20.0, min_depth()));
  }
  // How far the inner surface lies at least below the fitted outer one: 0.3 mm, or a material's
  // minimum thickness below the outer surface it is given (set below the fitted one by the
  // under-contour, unless the inner surface follows it down). Fitted to the bone, at least half
  // a millimetre more than the fit's smallest feature: thinner shell (a mirrored temporal
  // squama of 1.5 mm) would be opened away by the fit and leave a hole by the rim.
  double min_depth() const {
    const double fit = params_.fit_to_bone_mm > 0.0 && params_.fit_keeps_shell_thick
                           ? params_.trim.min_feature_mm + 0.5
                           : 0.0;
    if (!params_.material) return std::max(0.3, fit);
    const bool plate = !std::isnan(params_.material->thickness_mm);
    return params_.material->min_thickness_mm + (plate ? 0.0 : under_contour());
  }
  // Outward normal of the outer surface: from the spline's gradient (planar), or the ray
  // direction (radial; the surfaces of a skull are nearly perpendicular to rays from inside).
  Eigen::Vector3d outer_normal(const Eigen::Vector2d& q) const {
    if (f_.radial) return f_.up(q);
    const Eigen::Vector2d g = outer_tps_.gradient(q);
    return Eigen::Vector3d(f_.n - g.x() * f_.e1 - g.y() * f_.e2).normalized();
  }
  double offset(const Eigen::Vector2d& q) const {
    if (thickness_from_markers_) return depth(q);
    return params_.material ? std::max(result_.thickness_used_mm, min_depth())
                            : result_.thickness_used_mm;
  }
  PolarPolygon polygon(const std::vector<Eigen::Vector3d>& edges) const {
    PolarPolygon poly{center_, {}, {}, {}};
    for (const auto& p : edges) {
      poly.point.push_back(f_.uv(p));
      poly.angle.push_back(PolarPolygon::angle_of(center_, f_.uv(p)));
      poly.extra.push_back(0.0);
    }
    poly.sort();
    return poly;
  }

  // A rim point taken `d` beyond the opening at `q` (along `out`, `near` mm from the bone) that
  // has not yet crossed the bone's surface, while the bone comes nearer further out: at a
  // corner or a burr hole of the opening the ray runs along a cut face, and the shell would
  // stop short of the bone there. It goes on in half millimetres until it has crossed the
  // surface (and half a millimetre into the bone), up to twice the reach, as long as the bone
  // comes nearer by a fifth of each step (a ray at 12° or more to the surface it approaches);
  // where it comes no nearer (the surface riding over the outer table), is already within the
  // bridging of cracks (half a millimetre) or is never crossed, the point stays at `d`.
  template <class Lift>
  void reach_the_bone(const Eigen::Vector2d& q, const Eigen::Vector2d& out, double d, double near,
                      const Lift& lift, Eigen::Vector3d& point) const {
    constexpr double kStep = 0.5, kMinApproach = 0.2 * kStep, kBridged = 0.5;
    if (near < kBridged) return;
    Eigen::Vector3d previous = lift(q);
    for (double e = 1.0; e < d + 0.5; e += 1.0) {
      const Eigen::Vector3d p = e < d ? lift(q + e * out) : point;
      if (bone_->first_hit(previous, p)) return;
      previous = p;
    }
    const double reach = 2.0 * kFitReach * std::max(0.0, params_.fit_to_bone_mm);
    for (double e = d + kStep; e <= reach + 1e-9; e += kStep) {
      const Eigen::Vector3d p = lift(q + e * out);
      if (bone_->first_hit(previous, p)) {
        point = p;
        const Eigen::Vector3d deeper = lift(q + (e + kStep) * out);
        if (e + kStep <= reach + 1e-9 && !bone_->first_hit(p, deeper)) point = deeper;
        return;
      }
      const double now = bone_->closest(p).distance;
      if (now > near - kMinApproach) return;
      near = now;
      previous = p;
    }
  }

  // One rim in 3D along `poly` at the rim's angles: on the surface `tps` (or the outer one set
  // in by the thickness), beyond the opening into the bone when fitting to it, snapped onto the
  // bone between markers.
  std::vector<Eigen::Vector3d> rim_points(const PolarPolygon& poly, const Height* tps) const {
    const size_t n_rim = angles_.size();
    const double fit_margin = skull_ && bone_ ? std::max(0.0, params_.fit_to_bone_mm) : 0.0;
    std::vector<Eigen::Vector3d> pts(n_rim);
    auto lift_rim = [&](const Eigen::Vector2d& q) {
      if (tps) return f_.lift(q, (*tps)(q));
      // No inner markers: the outer rim offset inwards along the surface normal.
      return Eigen::Vector3d(f_.lift(q, offset_base(q)) - offset(q) * outer_normal(q));
    };
    for (size_t k = 0; k < n_rim; ++k) {
      const Eigen::Vector2d q = poly.at(angles_[k]).first;
      pts[k] = lift_rim(q);
      // Fitting to the bone: the rim goes beyond the opening, into the bone of the cut face,
      // to be trimmed there — only where there is bone to meet (not over an orbit). Where the
      // cut face is oblique, the surface beyond the rim first passes over the missing wedge:
      // the bone is sought further out, up to kFitReach times the margin.
      bool extended = false;
      if (fit_margin > 0.0 && onlay() > 0.0 && (q - center_).norm() > 1e-9) {
        // A plate laid on the bone reaches its overlap beyond the rim, over the outer table.
        pts[k] = lift_rim(q + onlay() * (q - center_).normalized());
        extended = true;
      } else if (fit_margin > 0.0 && (q - center_).norm() > 1e-9) {
        const Eigen::Vector2d out = (q - center_).normalized();
        for (double d = fit_margin; d <= kFitReach * fit_margin + 1e-9; d += 1.0) {
          const Eigen::Vector3d beyond = lift_rim(q + d * out);
          const double near = bone_->closest(beyond).distance;
          if (near < 0.5 * fit_margin) {
            pts[k] = beyond;
            extended = true;
            if (params_.fit_reaches_the_bone) reach_the_bone(q, out, d, near, lift_rim, pts[k]);
            break;
          }
        }
      }
      const bool exact = (is_marker_angle_[k] && tps != nullptr) || extended;
      // An inner rim set in from the outer one is not snapped: its nearest bone is often the
      // cut face far along the rim, and snapping it there makes spikes.
      if (bone_ && params_.snap_rim_to_skull && !exact && tps != nullptr) {
        const auto c = bone_->closest(pts[k]);
        // The snapped point must keep its place in the rim's angular order (else the cap
        // folds) and not land on its predecessor (else the wall gets a zero-area face).
        const double a = angles_[k];
        const double gap =
            0.45 * std::min(std::remainder(angles_[(k + 1) % n_rim] - a, kTwoPi),
                            std::remainder(a - angles_[(k + n_rim - 1) % n_rim], kTwoPi));
        const double moved =
            std::abs(std::remainder(PolarPolygon::angle_of(center_, f_.uv(c.point)) - a, kTwoPi));
        const bool collides = k > 0 && (c.point - pts[k - 1]).norm() < 0.05;
        if (c.distance <= params_.max_rim_snap_mm && moved < gap && !collides) pts[k] = c.point;
      }
    }
    return pts;
  }

  // The rim as a polygon whose `extra` is the rim's height above the surface the cap would have
  // without it (its snapping), which fades in towards the rim.
  PolarPolygon rim_polygon(const std::vector<Eigen::Vector3d>& rim, const Height* tps) const {
    PolarPolygon poly{center_, {}, {}, {}};
    for (const auto& p : rim) {
      const Eigen::Vector2d q = f_.uv(p);
      poly.point.push_back(q);
      poly.angle.push_back(PolarPolygon::angle_of(center_, q));
      const double base = tps ? (*tps)(q) : f_.h(p);
      poly.extra.push_back(f_.h(p) - base);
    }
    poly.sort();
    return poly;
  }

  // One surface's cap: rings shrinking from the rim to the centre, the rim's height correction
  // (snapping) fading in as s⁴ towards the rim. Its triangles (counter-clockwise in the
  // parametrisation) and the index of its first rim vertex in the soup.
  std::pair<std::vector<Eigen::Vector3i>, int> build_cap(const std::vector<Eigen::Vector3d>& rim,
                                                         const Height* tps,
                                                         bool offset_from_outer) {
    // The rim's correction is measured from the surface the cap would have without it: for an
    // inner surface set in from the outer one, that is the outer height less the offset (not
    // the outer height, which counted the offset twice at the rim).
    const Height offset_height = [&](const Eigen::Vector2d& q) {
      return f_.h(Eigen::Vector3d(f_.lift(q, offset_base(q)) - offset(q) * outer_normal(q)));
    };
    const PolarPolygon poly = rim_polygon(rim, offset_from_outer ? &offset_height : tps);
    auto surface_point = [&](const Eigen::Vector2d& q, double correction) {
      if (!offset_from_outer) return f_.lift(q, (*tps)(q) + correction);
      return Eigen::Vector3d(f_.lift(q, offset_base(q) + correction) - offset(q) * outer_normal(q));
    };
    const size_t n_rim = angles_.size();
    // Where the cap's points lie in the parametrisation, the centre first and then ring by
    // ring; their heights (thin-plate splines over every marker, the bulk of the shell's time
    // on a large opening) are evaluated on all threads, each point once, in this order.
    std::vector<std::pair<Eigen::Vector2d, double>> at{{center_, 0.0}};  // point, correction
    std::vector<std::vector<double>> ring_angles(static_cast<size_t>(std::max(0, n_rings_ - 1)));
    for (int k = 1; k < n_rings_; ++k) {
      const double s = static_cast<double>(k) / n_rings_;
      const int count = std::max(6, static_cast<int>(std::lround(static_cast<double>(n_rim) * s)));
      for (int j = 0; j < count; ++j) {
        const double a = start_ + kTwoPi * (j + 0.5) / count;
        const auto [boundary, correction] = poly.at(a);
        at.emplace_back(center_ + s * (boundary - center_), std::pow(s, 4) * correction);
        ring_angles[static_cast<size_t>(k - 1)].push_back(a);
      }
    }
    const int center_vertex = static_cast<int>(soup_.vertices.size());
    soup_.vertices.resize(soup_.vertices.size() + at.size());
    parallel_for(
        at.size(),
        [&](size_t first, size_t last) {
          for (size_t i = first; i < last; ++i)
            soup_.vertices[center_vertex + i] = surface_point(at[i].first, at[i].second);
        },
        64);
    std::vector<Eigen::Vector3i> tris;
    Ring previous;
    int first = center_vertex + 1;
    for (int k = 1; k < n_rings_; ++k) {
      const std::vector<double>& angles = ring_angles[static_cast<size_t>(k - 1)];
      Ring ring = make_ring(angles, first, start_, false);
      first += static_cast<int>(angles.size());
      if (k == 1) {
        for (size_t j = 0; j < ring.size(); ++j)
          tris.emplace_back(center_vertex, ring[j].vertex, ring[(j + 1) % ring.size()].vertex);
      } else {
        zipper(previous, ring, tris);
      }
      previous = std::move(ring);
    }
    const int rim_first = static_cast<int>(soup_.vertices.size());
    std::vector<double> rim_angles;
    for (const auto& p : rim) {
      soup_.vertices.push_back(p);
      rim_angles.push_back(PolarPolygon::angle_of(center_, f_.uv(p)));
    }
    zipper(previous, make_ring(rim_angles, rim_first, start_, true), tris);
    // The zipper winds every triangle the same way; turn the whole cap, if need be, so it
    // runs counter-clockwise in the parametrisation (normal outwards). Triangles are never
    // turned one by one: that would break the mesh where a sharp notch of the rim folds one.
    double signed_area = 0.0;
    for (const auto& t : tris) {
      const Eigen::Vector2d a = f_.uv(soup_.vertices[t[0]]), b = f_.uv(soup_.vertices[t[1]]),
                            c = f_.uv(soup_.vertices[t[2]]);
      signed_area += (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
    }
    if (signed_area < 0)
      for (auto& t : tris) std::swap(t[1], t[2]);
    return std::make_pair(tris, rim_first);
  }

  const std::vector<Marker>& markers_;
  const SkullMesh* skull_;
  const SurfaceLocator* skull_locator_;
  const ImplantParams& params_;
  ImplantResult& result_;
  SkullMesh& mesh_;  // result_.mesh, or where the caller keeps the shell before fitting it
  std::unique_ptr<SurfaceLocator> own_locator_;
  const SurfaceLocator* bone_ = nullptr;
  std::vector<Eigen::Vector3d> outer_, outer_edges_, inner_, inner_edges_;
  bool has_inner_ = false;
  Eigen::Vector3d marker_centroid_ = Eigen::Vector3d::Zero();
  Frame f_;
  ThinPlateSpline outer_tps_, thickness_tps_;
  bool thickness_from_markers_ = false;
  // The outer surface is set `under_contour` below the fitted one. An inner surface set in from
  // it by a thickness of the material's follows it down (the plate keeps its thickness); one
  // set in by the bone's thickness, or fitted to inner markers, stays at the inner table.
  double under_contour() const {
    return params_.material ? std::max(0.0, params_.material->under_contour_mm) : 0.0;
  }
  // A plate laid on the bone is raised by its thickness: its inner surface is the fitted outer
  // one.
  double onlay() const { return params_.material ? params_.material->onlay_mm : 0.0; }
  double raise() const { return onlay() > 0.0 ? params_.material->thickness_mm : 0.0; }
  // Where the plate lies: the fitted outer surface, or the bone's outer surface where that
  // stands higher (a brow ridge the fitted surface passes under): the first bone met coming in
  // from 20 mm outside along the surface's normal line.
  double onlay_base(const Eigen::Vector2d& q) const {
    const double fitted = outer_tps_(q);
    if (!bone_) return fitted;
    const auto hit =
        bone_->first_hit(f_.lift(q, fitted + kOnlaySearchMm), f_.lift(q, fitted - kOnlaySearchMm));
    return hit ? std::max(fitted, f_.h(hit->point)) : fitted;
  }
  double offset_base(const Eigen::Vector2d& q) const {
    if (onlay() > 0.0) return onlay_base(q) + raise();
    const bool plate = params_.material && !std::isnan(params_.material->thickness_mm);
    return outer_tps_(q) - (plate ? under_contour() : 0.0);
  }
  const Height outer_height_ = [this](const Eigen::Vector2d& q) {
    return onlay() > 0.0 ? onlay_base(q) + raise() : outer_tps_(q) - under_contour();
  };
  const Height inner_height_ = [this](const Eigen::Vector2d& q) {
    return outer_tps_(q) - depth(q);
  };
  Eigen::Vector2d center_ = Eigen::Vector2d::Zero();
  PolarPolygon outer_poly_, inner_poly_;
  double res_ = 1.0;
  std::vector<double> angles_;
  std::vector<char> is_marker_angle_;
  std::vector<Eigen::Vector3d> outer_rim_, inner_rim_;
  int n_rings_ = 2;
  double start_ = 0.0;
  TriangleSoup soup_;
};

// The shell, meshed in `shell` when given (the result's mesh is then left empty).
ImplantResult build_shell(const std::vector<Marker>& markers, const SkullMesh* skull,
                          const SurfaceLocator* skull_locator, const ImplantParams& params,
                          SkullMesh* shell) {
  ImplantResult result;
  ShellBuilder b(markers, skull, skull_locator, params, result, shell ? *shell : result.mesh);
  if (!b.gather_markers()) return result;
  b.set_frame();
  if (!b.markers_within_cap() || !b.fit_surfaces() || !b.rim_angles()) return result;
  b.rims();
  if (!b.ring_count()) return result;
  b.assemble();
  b.finish();
  return result;
}

ImplantResult build_delaunay(const std::vector<Marker>& markers, const ImplantParams& params) {
  ImplantResult result;
  if (markers.size() < 4) {
    result.status = ImplantResult::Status::TooFewMarkers;
    result.message =
        "Delaunay 3D needs at least 4 markers (" + std::to_string(markers.size()) + " given)";
    return result;
  }
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  for (const auto& m : markers) pts->InsertNextPoint(m.position.data());
  vtkNew<vtkPolyData> cloud;
  cloud->SetPoints(pts);
  vtkNew<vtkDelaunay3D> del;
  del->SetInputData(cloud);
  del->SetAlpha(params.delaunay_alpha);
  del->SetTolerance(params.delaunay_tolerance);
  del->SetOffset(params.delaunay_offset);
  vtkNew<vtkDataSetSurfaceFilter> surface;
  surface->SetInputConnection(del->GetOutputPort());
  vtkNew<vtkTriangleFilter> tri;
  tri->SetInputConnection(surface->GetOutputPort());
  tri->Update();
  vtkPolyData* pd = tri->GetOutput();
  TriangleSoup soup;
  for (vtkIdType i = 0; i < pd->GetNumberOfPoints(); ++i) {
    double p[3];
    pd->GetPoint(i, p);
    soup.vertices.emplace_back(p[0], p[1], p[2]);
  }
  vtkNew<vtkIdList> ids;
  for (pd->GetPolys()->InitTraversal(); pd->GetPolys()->GetNextCell(ids);)
    if (ids->GetNumberOfIds() == 3)
      soup.triangles.emplace_back(ids->GetId(0), ids->GetId(1), ids->GetId(2));
  if (soup.triangles.empty()) {
    result.message = "Delaunay 3D produced no surface (markers coplanar, or alpha too small)";
    return result;
  }
  if (signed_volume(soup) < 0)
    for (auto& t : soup.triangles) std::swap(t[1], t[2]);
  build_mesh(soup, result.mesh);
  result.watertight = is_watertight(result.mesh);
  result.status = ImplantResult::Status::Built;
  result.message = result.watertight ? "Delaunay 3D surface (watertight)"
                                     : "Delaunay 3D surface (not watertight)";
  return result;
}

}  // namespace

ImplantResult build_implant(const std::vector<Marker>& markers, const SkullMesh* skull,
                            const ImplantParams& params) {
  return build_implant(markers, skull, nullptr, params);
}

namespace {

// A result that was not built, and why.
ImplantResult refused(const std::string& why) {
  ImplantResult r;
  r.message = why;
  return r;
}

// Why the parameters, the material or the clearance zones cannot be applied, or empty.
std::string finishing_problem(const ImplantParams& params, const SkullMesh* skull) {
  if (std::string problem = range_problems("the implant's", params); !problem.empty())
    return problem;
  if (params.material) {
    const std::string problem = material_problem(*params.material);
    if (!problem.empty()) return params.material->name + ": " + problem;
  }
  if (params.perforations.any()) {
    if (params.method != ImplantMethod::Shell) return "perforations need the shell method";
    const std::string problem = perforation_problem(params.perforations);
    if (!problem.empty()) return problem;
  }
  if (params.tabs.any()) {
    if (params.method != ImplantMethod::Shell) return "fixation tabs need the shell method";
    if (!skull || skull->n_faces() == 0) return "fixation tabs are laid on the skull: give it";
    if (params.material && params.material->onlay_mm > 0.0)
      return params.material->name +
             " is laid on the bone and screwed through its own overlap: it has no tabs";
    const std::string problem = tab_problem(
        resolved(params.tabs, params.material ? params.material->min_thickness_mm
                                              : std::numeric_limits<double>::quiet_NaN()));
    if (!problem.empty()) return problem;
  }
  if (params.clearance_zones.size() > kMaxClearanceZones)
    return "at most " + std::to_string(kMaxClearanceZones) + " clearance zones";
  for (size_t k = 0; k < params.clearance_zones.size(); ++k) {
    const std::string problem = zone_problem(params.clearance_zones[k]);
    if (!problem.empty()) return "clearance zone " + std::to_string(k + 1) + ": " + problem;
  }
  const bool finished = !params.clearance_zones.empty() ||
                        (params.material && (params.material->edge_clearance_mm > 0.0 ||
                                             params.material->under_contour_mm > 0.0 ||
                                             params.material->onlay_mm > 0.0));
  if (finished && params.method != ImplantMethod::Shell)
    return "an edge clearance, under-contour or onlay needs the shell method";
  if (finished && (params.fit_to_bone_mm <= 0.0 || !skull || skull->n_faces() == 0))
    return "an edge clearance, under-contour or onlay is made by fitting the implant to the "
           "bone: set fit to bone (4 mm) with the skull";
  return {};
}

// A margin in millimetres as the messages write it ("4", "4.5").
std::string margin_text(double mm) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.1f", mm);
  std::string t = buf;
  if (t.size() > 2 && t.compare(t.size() - 2, 2, ".0") == 0) t.resize(t.size() - 2);
  return t;
}

// The fit to the bone again from other margins, when the fitted implant's edge stands off the
// bone by more than kRimGapTargetMm over an arc (ImplantParams::fit_margin_search). `fitted`
// holds the fit from params.fit_to_bone_mm and receives the one kept; `r` (the shell's result)
// takes the kept shell's figures and says which margin was used and why.
void search_fit_margin(const std::vector<Marker>& markers, const SkullMesh& skull,
                       const SurfaceLocator* skull_locator, const ImplantParams& params,
                       ImplantResult& r, SkullMesh& fitted) {
  std::unique_ptr<SurfaceLocator> own;
  if (!skull_locator) own = std::make_unique<SurfaceLocator>(skull);
  const SurfaceLocator& bone = skull_locator ? *skull_locator : *own;
  // The gap as the quality report judges it: with a clearance asked, its excess over it.
  const double clearance = params.material ? params.material->edge_clearance_mm : 0.0;
  const bool asked = clearance > 0.0 || !params.clearance_zones.empty();
  const RimGap first =
      rim_gap(fitted, bone, asked, clearance, params.clearance_zones, params.scan_ends);
  if (first.mm <= kRimGapTargetMm) return;
  const double asked_margin = params.fit_to_bone_mm;
  for (const double step : kFitMarginSteps) {
    const double margin = asked_margin + step;
    if (margin < kMinSearchedMarginMm || margin > kMaxSearchedMarginMm) continue;
    ImplantParams other = params;
    other.fit_to_bone_mm = margin;
    SkullMesh shell, trimmed;
    ImplantResult s = build_shell(markers, &skull, &bone, other, &shell);
    if (!s.usable()) continue;
    const TrimToBoneResult t = trim_to_bone(shell, skull, other.trim, trimmed, &bone);
    if (!t.usable()) continue;
    const RimGap gap =
        rim_gap(trimmed, bone, asked, clearance, params.clearance_zones, params.scan_ends);
    if (gap.mm > kRimGapTargetMm) continue;
    fitted = trimmed;
    r.thickness_used_mm = s.thickness_used_mm;
    r.rim_marker_error_mm = s.rim_marker_error_mm;
    r.rim_points = s.rim_points;
    r.fit_to_bone_used_mm = margin;
    char why[200];
    std::snprintf(why, sizeof(why),
                  "built %s mm over the bone instead of %s: at %s mm its edge stood %.2f mm %s",
                  margin_text(margin).c_str(), margin_text(asked_margin).c_str(),
                  margin_text(asked_margin).c_str(), first.mm,
                  asked ? "further off the bone than the clearance asked" : "off the bone");
    r.fit_margin_note = why + (first.at ? at_point_text(*first.at) : std::string());
    r.message += "; " + r.fit_margin_note;
    return;
  }
}

}  // namespace

ImplantResult build_implant(const std::vector<Marker>& markers, const SkullMesh* skull,
                            const SurfaceLocator* skull_locator, const ImplantParams& given) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::string problem = finishing_problem(given, skull);
  // The material's thickness replaces the plan's inner surface; its clearance is the fit's.
  ImplantParams params = given;
  std::vector<Marker> outer_only;
  const bool plate = given.material && !std::isnan(given.material->thickness_mm);
  if (plate) {
    params.thickness_mm = given.material->thickness_mm;
    for (const Marker& m : markers)
      if (is_outer(m.type)) outer_only.push_back(m);
  }
  // The fit to the bone leaves nothing thinner than the material's minimum (and keeps a plate
  // of the material's thickness, which the default feature size would take away).
  params.trim.scan_ends = given.scan_ends;
  if (given.material) params.trim.min_feature_mm = given.material->min_thickness_mm;
  if (given.material && given.material->edge_clearance_mm > 0.0)
    params.trim.clearance_mm =
        std::max(params.trim.clearance_mm.value_or(0.0), given.material->edge_clearance_mm);
  if (!given.clearance_zones.empty()) {
    if (!params.trim.clearance_mm) params.trim.clearance_mm = 0.0;
    params.trim.zones = given.clearance_zones;
  }
  const std::vector<Marker>& used = plate ? outer_only : markers;
  // The shell, then the fit to the bone, the tabs and the holes, each meshed anew: each stage
  // meshes into the next one's input and the last into the result (OpenMesh meshes are
  // copied, not moved, and a copy costs mostly the faulting in of fresh pages:
  // docs/decisions/0030-memory-huge-pages-one-arena-no-copies.md).
  const bool fitted = params.method == ImplantMethod::Shell && params.fit_to_bone_mm > 0.0 &&
                      skull && skull->n_faces() > 0;
  const bool tabbed = params.tabs.any(), drilled = params.perforations.any();
  const bool staged = params.method == ImplantMethod::Shell && (fitted || tabbed || drilled);
  SkullMesh shell, fitted_mesh, with_tabs;
  // One result, made where it is returned: a function that returns one of two named results
  // copies the one it returns.
  ImplantResult r = !problem.empty() ? refused(problem)
                    : params.method == ImplantMethod::Shell
                        ? build_shell(used, skull, skull_locator, params, staged ? &shell : nullptr)
                        : build_delaunay(used, params);
  const SkullMesh* current = staged ? &shell : &r.mesh;  // the implant as the stages left it
  StageClock clock(r.stage_seconds, t0);
  clock.mark("shell");
  if (r.usable() && fitted) {
    SkullMesh& out = tabbed || drilled ? fitted_mesh : r.mesh;
    const TrimToBoneResult t = trim_to_bone(*current, *skull, params.trim, out, skull_locator);
    clock.mark("fit");
    for (const auto& [stage, seconds] : t.stage_seconds)
      r.stage_seconds.emplace_back("fit: " + stage, seconds);
    if (t.usable()) {
      current = &out;
      r.fit_to_bone_used_mm = params.fit_to_bone_mm;
      if (params.fit_margin_search && !(params.material && params.material->onlay_mm > 0.0)) {
        search_fit_margin(used, *skull, skull_locator, params, r, out);
        clock.mark("fit margins");
      }
      r.watertight = is_watertight(out);
    } else {
      r.status = ImplantResult::Status::Failed;
      r.message = "fitting to the bone: " + t.message;
    }
  }
  // The outer side of tabs and holes faces away from the rays' centre (or the skull's centre).
  Eigen::Vector3d inside = params.radial_center.value_or(Eigen::Vector3d::Zero());
  if (!params.radial_center && skull && skull->n_vertices() > 0) inside = vertex_centroid(*skull);
  if (r.usable() && tabbed) {
    std::unique_ptr<SurfaceLocator> own;
    if (!skull_locator) own = std::make_unique<SurfaceLocator>(*skull);
    const TabParams tabs =
        resolved(params.tabs, params.material ? params.material->min_thickness_mm
                                              : std::numeric_limits<double>::quiet_NaN());
    SkullMesh& out = drilled ? with_tabs : r.mesh;
    TabResult t =
        add_fixation_tabs(*current, skull_locator ? *skull_locator : *own, inside, tabs, out);
    clock.mark("tabs");
    if (t.usable()) {
      current = &out;
      r.tabs = std::move(t.tabs);
      r.watertight = is_watertight(out);
      r.message += "; " + t.message;
    } else {
      r.status = ImplantResult::Status::Failed;
      r.message = "fixation tabs: " + t.message;
    }
  }
  if (r.usable() && drilled) {
    PerforationParams holes = params.perforations;
    if (params.material) holes.min_thickness_mm = params.material->min_thickness_mm;
    PerforateResult p = perforate(*current, inside, holes, r.mesh);
    clock.mark("holes");
    if (p.usable()) {
      current = &r.mesh;
      r.holes = std::move(p.holes);
      r.watertight = is_watertight(r.mesh);
      r.message += "; " + p.message;
    } else {
      r.status = ImplantResult::Status::Failed;
      r.message = "perforations: " + p.message;
    }
  }
  // A stage that failed leaves the implant as the stage before it made it.
  if (current != &r.mesh) r.mesh = *current;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

ImplantParams live_preview_params(ImplantParams params) {
  params.fit_to_bone_mm = 0.0;
  params.clearance_zones.clear();
  params.tabs = TabParams{};
  params.perforations = PerforationParams{};
  if (params.material) {
    params.material->edge_clearance_mm = 0.0;
    params.material->under_contour_mm = 0.0;
    params.material->onlay_mm = 0.0;
  }
  return params;
}

}  // namespace cranioplan
