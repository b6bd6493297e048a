#include "cranioplan/algorithms/implant/rim_gap.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <tuple>

#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/model/parallel.h"

namespace cranioplan {

std::string at_point_text(const Eigen::Vector3d& p) {
  char buf[96];
  std::snprintf(buf, sizeof(buf), " at (%.1f, %.1f, %.1f) mm", p.x(), p.y(), p.z());
  return buf;
}

double worst_arc_gap(const std::vector<double>& angle, const std::vector<double>& distance,
                     double arc_rad, size_t* where) {
  const size_t n = std::min(angle.size(), distance.size());
  if (n == 0) return 0.0;
  struct Point {
    double angle;  // in [0, 2π)
    double distance;
    size_t index;  // in the caller's arrays
    bool operator<(const Point& o) const {
      return std::tie(angle, distance, index) < std::tie(o.angle, o.distance, o.index);
    }
  };
  std::vector<Point> at(n);
  for (size_t i = 0; i < n; ++i) {
    const double a = std::fmod(angle[i], 2 * M_PI);
    at[i] = {a < 0 ? a + 2 * M_PI : a, distance[i], i};
  }
  std::sort(at.begin(), at.end());
  const double w = std::clamp(arc_rad, 0.0, 2 * M_PI);
  auto angle_of = [&](size_t k) { return at[k % n].angle + (k >= n ? 2 * M_PI : 0.0); };
  // An arc's points are a run of the sorted points; the arcs whose minimum can be the largest
  // hold the smallest runs: an arc that begins just past point j, (a_j, a_j + w], and, where
  // the next point lies more than w further on, that point alone. Their minima by a sliding
  // window (a deque of increasing distances) over the points taken twice around.
  double worst = 0.0;
  size_t worst_at = at[0].index;
  auto consider = [&](size_t k) {
    if (at[k % n].distance > worst) {
      worst = at[k % n].distance;
      worst_at = at[k % n].index;
    }
  };
  std::deque<size_t> window;
  size_t next = 1;  // the first point not yet in the window
  for (size_t j = 0; j < n; ++j) {
    while (!window.empty() && window.front() <= j) window.pop_front();
    if (next <= j) next = j + 1;
    while (next < j + n && angle_of(next) <= angle_of(j) + w) {
      while (!window.empty() && at[window.back() % n].distance >= at[next % n].distance)
        window.pop_back();
      window.push_back(next++);
    }
    consider(window.empty() ? j + 1 : window.front());  // else the next point, alone
  }
  if (where) *where = worst_at;
  return worst;
}

Eigen::Vector3d plate_axis(const SkullMesh& implant, const Eigen::Vector3d& c) {
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (auto vh : implant.vertices()) {
    const Eigen::Vector3d d = to_eigen(implant.point(vh)) - c;
    cov += d * d.transpose();
  }
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors().col(0);
}

bool across_plate(const Eigen::Vector3d& n, const Eigen::Vector3d& axis) {
  return std::abs(n.dot(axis)) >= std::cos(M_PI / 4);
}

RimSamples rim_samples(const SkullMesh& implant, const SurfaceLocator& bone,
                       const Eigen::Vector3d& c, const Eigen::Vector3d& axis,
                       std::vector<int> wall_vertices, const std::vector<Plane>& scan_ends) {
  std::sort(wall_vertices.begin(), wall_vertices.end());
  wall_vertices.erase(std::unique(wall_vertices.begin(), wall_vertices.end()), wall_vertices.end());
  const Eigen::Vector3d e1 = axis.unitOrthogonal(), e2 = axis.cross(e1);
  RimSamples s;
  const size_t walls = wall_vertices.size();
  s.angle.resize(walls);
  s.distance.resize(walls);
  s.nearest.resize(walls);
  parallel_for(
      walls,
      [&](size_t first, size_t last) {
        for (size_t i = first; i < last; ++i) {
          const Eigen::Vector3d p =
              to_eigen(implant.point(SkullMesh::VertexHandle(wall_vertices[i])));
          s.angle[i] = std::atan2((p - c).dot(e2), (p - c).dot(e1));
          const auto near = bone.closest(p);
          s.distance[i] = near.distance;
          s.nearest[i] = near.point;
          for (const Plane& end : scan_ends)
            if (std::abs(end.signed_distance(p)) <= kAtScanEndMm) {
              s.distance[i] = 0.0;  // the edge ends at the scan's end, not at bone
              s.nearest[i] = p;
            }
        }
      },
      256);
  s.vertices = std::move(wall_vertices);
  return s;
}

std::vector<double> clearance_excess(const RimSamples& s, double clearance_mm,
                                     const std::vector<ClearanceZone>& zones,
                                     const std::vector<bool>& skip) {
  std::vector<double> excess(s.distance.size());
  for (size_t i = 0; i < excess.size(); ++i)
    excess[i] = i < skip.size() && skip[i]
                    ? 0.0
                    : s.distance[i] - clearance_at(s.nearest[i], clearance_mm, zones);
  return excess;
}

RimGap rim_gap(const SkullMesh& implant, const SurfaceLocator& bone, bool clearance_asked,
               double clearance_mm, const std::vector<ClearanceZone>& zones,
               const std::vector<Plane>& scan_ends) {
  RimGap g;
  if (implant.n_faces() == 0) return g;
  const Eigen::Vector3d c = vertex_centroid(implant);
  const Eigen::Vector3d axis = plate_axis(implant, c);
  std::vector<int> wall;
  for (auto fh : implant.faces()) {
    const FaceCorners f = face_corners(implant, fh);
    const Eigen::Vector3d n = f.cross();
    if (n.norm() == 0 || across_plate(n.normalized(), axis)) continue;
    wall.insert(wall.end(), f.ids.begin(), f.ids.end());
  }
  const RimSamples s = rim_samples(implant, bone, c, axis, std::move(wall), scan_ends);
  if (s.vertices.empty()) return g;
  size_t at = 0;
  g.mm = clearance_asked
             ? worst_arc_gap(s.angle, clearance_excess(s, clearance_mm, zones), kRimArcRad, &at)
             : worst_arc_gap(s.angle, s.distance, kRimArcRad, &at);
  g.at = to_eigen(implant.point(SkullMesh::VertexHandle(s.vertices[at])));
  return g;
}

}  // namespace cranioplan
