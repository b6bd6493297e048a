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

#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/geometry/thin_plate_spline.h"
#include "cranioplan/algorithms/implant/trim_to_bone.h"
#include "cranioplan/algorithms/io/mesh_report.h"
#include "cranioplan/model/error.h"
#include "cranioplan/model/plane.h"

namespace cranioplan {

const char* to_string(ImplantMethod m) {
  return m == ImplantMethod::Shell ? "shell" : "delaunay3d";
}

namespace {

constexpr double kTwoPi = 2.0 * M_PI;
// Markers closer than this (mm, in the parametrisation) to an earlier one are not fitted.
constexpr double kMinMarkerSeparation = 1.0;
// Fitting to the bone seeks the bone to meet up to this many times the margin beyond the rim.
constexpr double kFitReach = 3.0;

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

ImplantResult build_shell(const std::vector<Marker>& markers, const SkullMesh* skull,
                          const SurfaceLocator* skull_locator, const ImplantParams& params) {
  ImplantResult result;
  // Edge markers first: where a surface marker lies next to an edge marker, the edge wins.
  std::vector<Eigen::Vector3d> outer, outer_edges, inner, inner_edges;
  for (const auto& m : markers) {
    if (m.type == MarkerType::OuterEdge) outer_edges.push_back(m.position);
    if (m.type == MarkerType::InnerEdge) inner_edges.push_back(m.position);
  }
  outer = outer_edges;
  inner = inner_edges;
  for (const auto& m : markers)
    if (!is_edge(m.type)) (is_outer(m.type) ? outer : inner).push_back(m.position);
  if (outer_edges.size() < 3) {
    result.status = ImplantResult::Status::TooFewMarkers;
    result.message = "the shell needs at least 3 outer edge markers (" +
                     std::to_string(outer_edges.size()) + " given)";
    return result;
  }
  const bool has_inner = inner_edges.size() >= 3;
  std::unique_ptr<SurfaceLocator> own_locator;
  if (!skull_locator && skull && skull->n_faces() > 0)
    own_locator = std::make_unique<SurfaceLocator>(*skull);
  const SurfaceLocator* bone = skull_locator ? skull_locator : own_locator.get();

  Eigen::Vector3d marker_centroid = Eigen::Vector3d::Zero();
  for (const auto& p : outer) marker_centroid += p;
  marker_centroid /= static_cast<double>(outer.size());
  Eigen::Vector3d skull_centre = marker_centroid;
  if (skull && skull->n_vertices() > 0) {
    skull_centre.setZero();
    for (auto vh : skull->vertices()) skull_centre += to_eigen(skull->point(vh));
    skull_centre /= static_cast<double>(skull->n_vertices());
  }
  Frame f;
  if (params.radial_center ||
      (skull && skull->n_vertices() > 0 && params.frame == ImplantFrame::Radial)) {
    f.radial = true;
    f.origin = params.radial_center ? *params.radial_center : skull_centre;
    Eigen::Vector3d axis = Eigen::Vector3d::Zero();
    f.scale = 0.0;
    for (const auto& p : outer_edges) {
      axis += (p - f.origin).normalized();
      f.scale += (p - f.origin).norm();
    }
    f.n = axis.normalized();
    f.scale /= static_cast<double>(outer_edges.size());
    // Across the axis towards the first edge marker: the same on the skull in any pose.
    f.e1 = unit_across(outer_edges.front() - f.origin, f.n);
    f.e2 = f.n.cross(f.e1);
  } else {
    // The plane of the outer markers, normal pointing away from the skull's centre.
    f.origin = marker_centroid;
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (const auto& p : outer) cov += (p - f.origin) * (p - f.origin).transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
    f.n = eig.eigenvectors().col(0);
    if (f.n.dot(f.origin - skull_centre) < 0) f.n = -f.n;
    f.e1 = eig.eigenvectors().col(2);
    f.e2 = f.n.cross(f.e1);
  }
  // Rays from the centre parametrise a cap, not more: a marker far off the axis (e.g. one
  // placed on the far wall of the skull through the opening) would stretch the height field
  // without bound.
  if (f.radial) {
    for (const auto& m : markers) {
      const Eigen::Vector3d d = m.position - f.origin;
      if (d.dot(f.n) < std::cos(75.0 * M_PI / 180.0) * d.norm()) {
        result.status = ImplantResult::Status::Failed;
        result.message = "marker " + std::to_string(m.id) +
                         " lies more than 75° from the defect's axis, seen from inside the skull: "
                         "it is probably on the far side of the skull (placed through the "
                         "opening?) — move or delete it";
        return result;
      }
    }
  }

  // The outer surface: a spline of heights through the outer markers. The inner surface: the
  // outer one less a thickness field, a spline through the inner markers' depths below the
  // outer surface. Thickness varies slowly, so its spline stays calm across the opening where
  // a spline of the inner heights themselves, pulled by noisy samples at the rim, can buckle.
  auto fit = [&](const std::vector<Eigen::Vector3d>& pts, size_t edges, ThinPlateSpline& tps,
                 const ThinPlateSpline* below) {
    std::vector<Eigen::Vector2d> uv;
    std::vector<double> h;
    for (const auto& p : pts) {
      uv.push_back(f.uv(p));
      h.push_back(below ? (*below)(f.uv(p)) - f.h(p) : f.h(p));
    }
    std::vector<double> smoothing(uv.size(), 0.0);
    for (size_t i = edges; i < smoothing.size(); ++i) smoothing[i] = params.surface_smoothing;
    return tps.fit(uv, h, smoothing, kMinMarkerSeparation, edges);
  };
  ThinPlateSpline outer_tps, thickness_tps;
  thickness_tps.set_quadratic_trend(false);
  if (!fit(outer, outer_edges.size(), outer_tps, nullptr)) {
    result.message = "the outer markers lie on a line: no surface can be fitted";
    return result;
  }
  if (has_inner && !fit(inner, inner_edges.size(), thickness_tps, &outer_tps)) {
    result.message = "the inner markers lie on a line: no surface can be fitted";
    return result;
  }
  // Without an inner rim, inner surface markers (six or more) still give the thickness field;
  // the inner rim is then the outer one offset by it.
  const bool thickness_from_markers = !has_inner && inner.size() >= 6 &&
                                      std::isnan(params.thickness_mm) &&
                                      fit(inner, 0, thickness_tps, &outer_tps);
  // Depths are kept between 0.3 mm and 20 mm: the inner surface never crosses the outer one.
  auto depth = [&](const Eigen::Vector2d& q) { return std::clamp(thickness_tps(q), 0.3, 20.0); };
  using Height = std::function<double(const Eigen::Vector2d&)>;
  const Height outer_height = [&](const Eigen::Vector2d& q) { return outer_tps(q); };
  const Height inner_height = [&](const Eigen::Vector2d& q) { return outer_tps(q) - depth(q); };
  // Outward normal of the outer surface: from the spline's gradient (planar), or the ray
  // direction (radial; the surfaces of a skull are nearly perpendicular to rays from inside).
  auto outer_normal = [&](const Eigen::Vector2d& q) {
    if (f.radial) return f.up(q);
    const Eigen::Vector2d g = outer_tps.gradient(q);
    return Eigen::Vector3d(f.n - g.x() * f.e1 - g.y() * f.e2).normalized();
  };
  result.thickness_used_mm =
      has_inner                ? 0.0
      : thickness_from_markers ? depth(Eigen::Vector2d::Zero())
      : !std::isnan(params.thickness_mm)
          ? params.thickness_mm
          : (bone ? measure_bone_thickness(outer_edges, marker_centroid, *bone) : 6.0);
  auto offset = [&](const Eigen::Vector2d& q) {
    return thickness_from_markers ? depth(q) : result.thickness_used_mm;
  };

  // Rim polygons around the centre of the outer edge markers.
  // Polar centre: the ray axis (radial; the rim is ordered around it), or the rim's centroid.
  Eigen::Vector2d center = Eigen::Vector2d::Zero();
  if (!f.radial) {
    for (const auto& p : outer_edges) center += f.uv(p);
    center /= static_cast<double>(outer_edges.size());
  }
  auto polygon = [&](const std::vector<Eigen::Vector3d>& edges) {
    PolarPolygon poly{center, {}, {}, {}};
    for (const auto& p : edges) {
      poly.point.push_back(f.uv(p));
      poly.angle.push_back(PolarPolygon::angle_of(center, f.uv(p)));
      poly.extra.push_back(0.0);
    }
    poly.sort();
    return poly;
  };
  const PolarPolygon outer_poly = polygon(outer_edges);
  const PolarPolygon inner_poly = has_inner ? polygon(inner_edges) : outer_poly;

  // Rim sample angles: every edge marker's, densified to the resolution along the outer rim.
  const double res = std::clamp(params.resolution_mm, 0.2, 10.0);
  std::vector<double> marker_angles = outer_poly.angle;
  if (has_inner)
    marker_angles.insert(marker_angles.end(), inner_poly.angle.begin(), inner_poly.angle.end());
  std::sort(marker_angles.begin(), marker_angles.end());
  marker_angles.erase(std::unique(marker_angles.begin(), marker_angles.end(),
                                  [](double a, double b) { return std::abs(a - b) < 1e-9; }),
                      marker_angles.end());
  std::vector<double> angles;
  std::vector<char> is_marker_angle;
  double rim_length = 0.0;
  for (size_t k = 0; k < marker_angles.size(); ++k) {
    const double a0 = marker_angles[k];
    const double a1 =
        k + 1 < marker_angles.size() ? marker_angles[k + 1] : marker_angles[0] + kTwoPi;
    rim_length += std::max((outer_poly.at(a1).first - outer_poly.at(a0).first).norm(),
                           (inner_poly.at(a1).first - inner_poly.at(a0).first).norm());
  }
  if (rim_length / res > 1e5) {
    result.status = ImplantResult::Status::Failed;
    result.message = "the rim through the edge markers is " +
                     format_count(std::lround(rim_length)) +
                     " mm long: the markers span too large a region (check markers far from the "
                     "defect)";
    return result;
  }
  for (size_t k = 0; k < marker_angles.size(); ++k) {
    const double a0 = marker_angles[k];
    const double a1 =
        k + 1 < marker_angles.size() ? marker_angles[k + 1] : marker_angles[0] + kTwoPi;
    const double len = std::max((outer_poly.at(a1).first - outer_poly.at(a0).first).norm(),
                                (inner_poly.at(a1).first - inner_poly.at(a0).first).norm());
    const int steps = std::max(1, static_cast<int>(std::ceil(len / res)));
    for (int s = 0; s < steps; ++s) {
      angles.push_back(a0 + (a1 - a0) * s / steps);
      is_marker_angle.push_back(s == 0);
    }
  }
  const size_t n_rim = angles.size();
  result.rim_points = static_cast<int>(n_rim);

  const double fit_margin = skull && bone ? std::max(0.0, params.fit_to_bone_mm) : 0.0;
  // Rim points in 3D, snapped onto the bone between markers.
  auto rim_points = [&](const PolarPolygon& poly, const Height* tps) {
    std::vector<Eigen::Vector3d> pts(n_rim);
    auto lift_rim = [&](const Eigen::Vector2d& q) {
      if (tps) return f.lift(q, (*tps)(q));
      // No inner markers: the outer rim offset inwards along the surface normal.
      return Eigen::Vector3d(f.lift(q, outer_tps(q)) - offset(q) * outer_normal(q));
    };
    for (size_t k = 0; k < n_rim; ++k) {
      const Eigen::Vector2d q = poly.at(angles[k]).first;
      pts[k] = lift_rim(q);
      // Fitting to the bone: the rim goes beyond the opening, into the bone of the cut face,
      // to be trimmed there — only where there is bone to meet (not over an orbit). Where the
      // cut face is oblique, the surface beyond the rim first passes over the missing wedge:
      // the bone is sought further out, up to kFitReach times the margin.
      bool extended = false;
      if (fit_margin > 0.0 && (q - center).norm() > 1e-9) {
        const Eigen::Vector2d out = (q - center).normalized();
        for (double d = fit_margin; d <= kFitReach * fit_margin + 1e-9; d += 1.0) {
          const Eigen::Vector3d beyond = lift_rim(q + d * out);
          if (bone->closest(beyond).distance < 0.5 * fit_margin) {
            pts[k] = beyond;
            extended = true;
            break;
          }
        }
      }
      const bool exact = (is_marker_angle[k] && tps != nullptr) || extended;
      // An inner rim set in from the outer one is not snapped: its nearest bone is often the
      // cut face far along the rim, and snapping it there makes spikes.
      if (bone && params.snap_rim_to_skull && !exact && tps != nullptr) {
        const auto c = bone->closest(pts[k]);
        // The snapped point must keep its place in the rim's angular order (else the cap
        // folds) and not land on its predecessor (else the wall gets a zero-area face).
        const double a = angles[k];
        const double gap =
            0.45 * std::min(std::remainder(angles[(k + 1) % n_rim] - a, kTwoPi),
                            std::remainder(a - angles[(k + n_rim - 1) % n_rim], kTwoPi));
        const double moved =
            std::abs(std::remainder(PolarPolygon::angle_of(center, f.uv(c.point)) - a, kTwoPi));
        const bool collides = k > 0 && (c.point - pts[k - 1]).norm() < 0.05;
        if (c.distance <= params.max_rim_snap_mm && moved < gap && !collides) pts[k] = c.point;
      }
    }
    return pts;
  };
  const std::vector<Eigen::Vector3d> outer_rim = rim_points(outer_poly, &outer_height);
  std::vector<Eigen::Vector3d> inner_rim =
      rim_points(inner_poly, has_inner ? &inner_height : nullptr);
  // Where both rims meet the same bone point the side wall would have no height: keep at
  // least 0.3 mm between them, inwards along the outer surface's normal.
  for (size_t k = 0; k < n_rim; ++k)
    if ((inner_rim[k] - outer_rim[k]).norm() < 0.3)
      inner_rim[k] = outer_rim[k] - 0.3 * outer_normal(f.uv(outer_rim[k]));

  // The surfaces' interiors: rings shrinking from the rim to the centre. The rim's height
  // correction (snapping) fades in as s⁴ towards the rim.
  auto rim_polygon = [&](const std::vector<Eigen::Vector3d>& rim, const Height* tps) {
    PolarPolygon poly{center, {}, {}, {}};
    for (const auto& p : rim) {
      const Eigen::Vector2d q = f.uv(p);
      poly.point.push_back(q);
      poly.angle.push_back(PolarPolygon::angle_of(center, q));
      const double base = tps ? (*tps)(q) : f.h(p);
      poly.extra.push_back(f.h(p) - base);
    }
    poly.sort();
    return poly;
  };
  double radius = 0.0;
  for (const auto& p : outer_rim) radius = std::max(radius, (f.uv(p) - center).norm());
  const int n_rings = std::max(2, static_cast<int>(std::ceil(radius / res)));
  const double start = angles.front() - 1e-6;
  const double vertices = 2.0 * n_rings * static_cast<double>(n_rim);
  if (vertices > 4e6) {
    result.status = ImplantResult::Status::Failed;
    char buf[200];
    std::snprintf(buf, sizeof(buf),
                  "the shell would need %.0f million vertices at %.2f mm: the markers span too "
                  "large a region (check markers far from the defect)",
                  vertices / 1e6, res);
    result.message = buf;
    return result;
  }

  TriangleSoup soup;
  auto build_cap = [&](const std::vector<Eigen::Vector3d>& rim, const Height* tps,
                       bool offset_from_outer) {
    // The rim's correction is measured from the surface the cap would have without it: for an
    // inner surface set in from the outer one, that is the outer height less the offset (not
    // the outer height, which counted the offset twice at the rim).
    const Height offset_height = [&](const Eigen::Vector2d& q) {
      return f.h(Eigen::Vector3d(f.lift(q, outer_tps(q)) - offset(q) * outer_normal(q)));
    };
    const PolarPolygon poly = rim_polygon(rim, offset_from_outer ? &offset_height : tps);
    auto surface_point = [&](const Eigen::Vector2d& q, double correction) {
      if (!offset_from_outer) return f.lift(q, (*tps)(q) + correction);
      return Eigen::Vector3d(f.lift(q, outer_tps(q) + correction) - offset(q) * outer_normal(q));
    };
    std::vector<Eigen::Vector3i> tris;
    const int center_vertex = static_cast<int>(soup.vertices.size());
    soup.vertices.push_back(surface_point(center, 0.0));
    Ring previous;
    for (int k = 1; k < n_rings; ++k) {
      const double s = static_cast<double>(k) / n_rings;
      const int count = std::max(6, static_cast<int>(std::lround(static_cast<double>(n_rim) * s)));
      std::vector<double> ring_angles;
      const int first = static_cast<int>(soup.vertices.size());
      for (int j = 0; j < count; ++j) {
        const double a = start + kTwoPi * (j + 0.5) / count;
        const auto [boundary, correction] = poly.at(a);
        soup.vertices.push_back(
            surface_point(center + s * (boundary - center), std::pow(s, 4) * correction));
        ring_angles.push_back(a);
      }
      Ring ring = make_ring(ring_angles, first, start, false);
      if (k == 1) {
        for (size_t j = 0; j < ring.size(); ++j)
          tris.emplace_back(center_vertex, ring[j].vertex, ring[(j + 1) % ring.size()].vertex);
      } else {
        zipper(previous, ring, tris);
      }
      previous = std::move(ring);
    }
    const int rim_first = static_cast<int>(soup.vertices.size());
    std::vector<double> rim_angles;
    for (const auto& p : rim) {
      soup.vertices.push_back(p);
      rim_angles.push_back(PolarPolygon::angle_of(center, f.uv(p)));
    }
    zipper(previous, make_ring(rim_angles, rim_first, start, true), tris);
    // The zipper winds every triangle the same way; turn the whole cap, if need be, so it
    // runs counter-clockwise in the parametrisation (normal outwards). Triangles are never
    // turned one by one: that would break the mesh where a sharp notch of the rim folds one.
    double signed_area = 0.0;
    for (const auto& t : tris) {
      const Eigen::Vector2d a = f.uv(soup.vertices[t[0]]), b = f.uv(soup.vertices[t[1]]),
                            c = f.uv(soup.vertices[t[2]]);
      signed_area += (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
    }
    if (signed_area < 0)
      for (auto& t : tris) std::swap(t[1], t[2]);
    return std::make_pair(tris, rim_first);
  };
  auto [outer_tris, outer_rim_first] = build_cap(outer_rim, &outer_height, false);
  auto [inner_tris, inner_rim_first] =
      build_cap(inner_rim, has_inner ? &inner_height : nullptr, !has_inner);
  soup.triangles = outer_tris;
  for (auto t : inner_tris) soup.triangles.emplace_back(t[0], t[2], t[1]);  // facing inwards
  // Side wall between rim k of both surfaces. The outer cap runs its rim o_k → o_k+1 and the
  // inner cap (facing inwards) i_k+1 → i_k, so the wall takes the opposite directions.
  for (size_t k = 0; k < n_rim; ++k) {
    const int o0 = outer_rim_first + static_cast<int>(k);
    const int o1 = outer_rim_first + static_cast<int>((k + 1) % n_rim);
    const int i0 = inner_rim_first + static_cast<int>(k);
    const int i1 = inner_rim_first + static_cast<int>((k + 1) % n_rim);
    soup.triangles.emplace_back(o1, o0, i0);
    soup.triangles.emplace_back(o1, i0, i1);
  }
  if (signed_volume(soup) < 0)  // inner surface above the outer one: markers swapped
    for (auto& t : soup.triangles) std::swap(t[1], t[2]);
  result.mesh = build_mesh(soup);

  for (const auto& m : markers) {
    if (!is_edge(m.type)) continue;
    const std::vector<Eigen::Vector3d>& rim =
        m.type == MarkerType::OuterEdge ? outer_rim : inner_rim;
    double best = std::numeric_limits<double>::infinity();
    for (const auto& p : rim) best = std::min(best, (p - m.position).norm());
    if (m.type == MarkerType::OuterEdge || has_inner)
      result.rim_marker_error_mm = std::max(result.rim_marker_error_mm, best);
  }
  result.watertight = report_mesh(result.mesh).watertight;
  result.status = ImplantResult::Status::Built;
  result.message = has_inner ? "shell through outer and inner markers"
                             : "shell through outer markers, inner surface offset by the thickness";
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
  result.mesh = build_mesh(soup);
  result.watertight = report_mesh(result.mesh).watertight;
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

ImplantResult build_implant(const std::vector<Marker>& markers, const SkullMesh* skull,
                            const SurfaceLocator* skull_locator, const ImplantParams& params) {
  const auto t0 = std::chrono::steady_clock::now();
  ImplantResult r = params.method == ImplantMethod::Shell
                        ? build_shell(markers, skull, skull_locator, params)
                        : build_delaunay(markers, params);
  if (r.usable() && params.method == ImplantMethod::Shell && params.fit_to_bone_mm > 0.0 && skull &&
      skull->n_faces() > 0) {
    TrimToBoneResult t = trim_to_bone(r.mesh, *skull, params.trim);
    if (t.usable()) {
      r.mesh = std::move(t.mesh);
      r.watertight = report_mesh(r.mesh).watertight;
    } else {
      r.status = ImplantResult::Status::Failed;
      r.message = "fitting to the bone: " + t.message;
    }
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace cranioplan
