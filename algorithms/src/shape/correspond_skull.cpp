#include "cranioplan/algorithms/shape/correspond_skull.h"

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <random>
#include <utility>

#include "cranioplan/algorithms/geometry/fit_sphere.h"
#include "cranioplan/algorithms/geometry/point_index.h"
#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/geometry/surface_samples.h"
#include "cranioplan/algorithms/shape/shape_model.h"
#include "cranioplan/model/parallel.h"

namespace cranioplan {
namespace {

constexpr double kReach = 400.0;  // mm: rays from the vault's centre leave the skull before this

}  // namespace

Icosphere icosphere(int subdivisions) {
  Icosphere s;
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  for (const auto& v : std::vector<Eigen::Vector3d>{{-1, t, 0},
                                                    {1, t, 0},
                                                    {-1, -t, 0},
                                                    {1, -t, 0},
                                                    {0, -1, t},
                                                    {0, 1, t},
                                                    {0, -1, -t},
                                                    {0, 1, -t},
                                                    {t, 0, -1},
                                                    {t, 0, 1},
                                                    {-t, 0, -1},
                                                    {-t, 0, 1}})
    s.vertices.push_back(v.normalized());
  s.faces = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
             {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
             {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int level = 0; level < subdivisions; ++level) {
    std::map<std::pair<int, int>, int> middle;
    auto mid = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      const auto it = middle.find(key);
      if (it != middle.end()) return it->second;
      s.vertices.push_back((s.vertices[a] + s.vertices[b]).normalized());
      const int id = static_cast<int>(s.vertices.size()) - 1;
      middle.emplace(key, id);
      return id;
    };
    std::vector<Eigen::Vector3i> next;
    next.reserve(s.faces.size() * 4);
    for (const auto& f : s.faces) {
      const int a = mid(f[0], f[1]), b = mid(f[1], f[2]), c = mid(f[2], f[0]);
      next.push_back({f[0], a, c});
      next.push_back({f[1], b, a});
      next.push_back({f[2], c, b});
      next.push_back({a, b, c});
    }
    s.faces = std::move(next);
  }
  return s;
}

namespace {

std::vector<std::vector<int>> neighbours(const Icosphere& s) {
  std::vector<std::vector<int>> n(s.vertices.size());
  for (const auto& f : s.faces)
    for (int k = 0; k < 3; ++k) {
      n[f[k]].push_back(f[(k + 1) % 3]);
      n[f[k]].push_back(f[(k + 2) % 3]);
    }
  for (auto& v : n) {
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
  }
  return n;
}

// Connected components of the directions where `in` is true (-1 elsewhere); their count.
int components(const std::vector<std::vector<int>>& nb, const std::vector<char>& in,
               std::vector<int>& label) {
  label.assign(nb.size(), -1);
  int count = 0;
  for (size_t seed = 0; seed < nb.size(); ++seed) {
    if (!in[seed] || label[seed] >= 0) continue;
    std::vector<int> stack{static_cast<int>(seed)};
    label[seed] = count;
    while (!stack.empty()) {
      const int v = stack.back();
      stack.pop_back();
      for (int w : nb[v])
        if (in[w] && label[w] < 0) {
          label[w] = count;
          stack.push_back(w);
        }
    }
    ++count;
  }
  return count;
}

// Keeps only the largest component of `in`.
void keep_largest(const std::vector<std::vector<int>>& nb, std::vector<char>& in) {
  std::vector<int> label;
  const int n = components(nb, in, label);
  if (n <= 1) return;
  std::vector<int> size(n, 0);
  for (int l : label)
    if (l >= 0) ++size[l];
  const int best = static_cast<int>(std::max_element(size.begin(), size.end()) - size.begin());
  for (size_t i = 0; i < in.size(); ++i) in[i] = label[i] == best;
}

std::optional<FittedSphere> sphere_of(const std::vector<Eigen::Vector3d>& pts) {
  std::vector<size_t> idx(pts.size());
  std::iota(idx.begin(), idx.end(), size_t{0});
  return fit_sphere(pts, idx);
}

// The 24 rotations of a cube.
std::vector<Eigen::Matrix3d> cube_rotations() {
  std::vector<Eigen::Matrix3d> out;
  const int perms[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1}, {1, 0, 2}, {0, 2, 1}, {2, 1, 0}};
  for (const auto& p : perms)
    for (int signs = 0; signs < 8; ++signs) {
      Eigen::Matrix3d R = Eigen::Matrix3d::Zero();
      for (int r = 0; r < 3; ++r) R(r, p[r]) = (signs >> r) & 1 ? -1.0 : 1.0;
      if (R.determinant() > 0.0) out.push_back(R);
    }
  return out;
}

// The starting rotations of the pose search: the 24 rotations of a cube (the scanner's axes
// turned by quarter turns), then 96 more spread over all rotations (a fixed random draw of unit
// quaternions), so that every pose lies within about 25° of a start.
std::vector<Eigen::Matrix3d> start_rotations() {
  std::vector<Eigen::Matrix3d> out = cube_rotations();
  std::mt19937 rng(20261207);
  std::normal_distribution<double> z(0.0, 1.0);
  for (int k = 0; k < 96; ++k) {
    Eigen::Quaterniond q(z(rng), z(rng), z(rng), z(rng));
    q.normalize();
    out.push_back(q.toRotationMatrix());
  }
  return out;
}

}  // namespace

std::vector<Eigen::Vector3d> vertex_sample(const SkullMesh& mesh, size_t count) {
  std::vector<Eigen::Vector3d> out;
  const size_t n = mesh.n_vertices(), step = std::max<size_t>(1, n / std::max<size_t>(1, count));
  for (size_t i = 0; i < n; i += step)
    out.push_back(to_eigen(mesh.point(SkullMesh::VertexHandle(static_cast<int>(i)))));
  return out;
}

ShapeTemplate make_shape_template(const SkullMesh& skull, const ShapeTemplateParams& params) {
  ShapeTemplate out;
  if (skull.n_faces() == 0) return out;
  const auto sphere = sphere_of(vertex_sample(skull, 20000));
  if (!sphere) return out;
  out.center = sphere->center;
  const SurfaceLocator bone(skull);
  const Icosphere ico = icosphere(std::clamp(params.subdivisions, 2, 6));
  const size_t n = ico.vertices.size();
  const double cos_tilt = std::cos(params.max_tilt_deg * M_PI / 180.0);
  std::vector<double> r_out(n, 0.0), r_in(n, 0.0);
  std::vector<char> kept(n, 0);
  parallel_for(
      n,
      [&](size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i) {
          const Eigen::Vector3d d = ico.vertices[i];
          const auto hits = bone.hits_along(out.center, out.center + kReach * d);
          if (hits.size() != 2) continue;
          const double t = hits[1].distance - hits[0].distance;
          if (t < params.min_thickness_mm || t > params.max_thickness_mm) continue;
          if (bone.face_normal(hits[0].face).dot(d) > -cos_tilt) continue;  // inner table faces in
          if (bone.face_normal(hits[1].face).dot(d) < cos_tilt) continue;   // outer faces out
          r_in[i] = hits[0].distance;
          r_out[i] = hits[1].distance;
          kept[i] = 1;
        }
      },
      64);
  const auto nb = neighbours(ico);
  keep_largest(nb, kept);
  // Gaps enclosed by the vault (every component of the rest but the largest) are filled from
  // their surroundings.
  std::vector<char> rest(n);
  for (size_t i = 0; i < n; ++i) rest[i] = !kept[i];
  std::vector<char> outside = rest;
  keep_largest(nb, outside);
  std::vector<int> gap;
  for (size_t i = 0; i < n; ++i)
    if (rest[i] && !outside[i]) gap.push_back(static_cast<int>(i));
  if (!gap.empty()) {
    double mean_out = 0.0, mean_in = 0.0;
    int count = 0;
    for (size_t i = 0; i < n; ++i)
      if (kept[i]) mean_out += r_out[i], mean_in += r_in[i], ++count;
    for (int g : gap) r_out[g] = mean_out / count, r_in[g] = mean_in / count;
    for (int it = 0; it < 200; ++it)
      for (int g : gap) {
        double so = 0.0, si = 0.0;
        for (int w : nb[g]) so += r_out[w], si += r_in[w];
        r_out[g] = so / nb[g].size();
        r_in[g] = si / nb[g].size();
      }
    for (int g : gap) kept[g] = 1;
  }
  for (int ring = 0; ring < params.border_rings; ++ring) {
    std::vector<char> next = kept;
    for (size_t i = 0; i < n; ++i)
      if (kept[i])
        for (int w : nb[i])
          if (!kept[w]) next[i] = 0;
    kept = std::move(next);
  }
  keep_largest(nb, kept);
  std::vector<int> index(n, -1);
  int count = 0;
  for (size_t i = 0; i < n; ++i)
    if (kept[i]) index[i] = count++;
  if (count < 100) return out;
  out.outer_count = count;
  out.points.resize(3, 2 * count);
  for (size_t i = 0; i < n; ++i)
    if (kept[i]) {
      out.points.col(index[i]) = out.center + r_out[i] * ico.vertices[i];
      out.points.col(count + index[i]) = out.center + r_in[i] * ico.vertices[i];
    }
  for (const auto& f : ico.faces) {
    if (index[f[0]] < 0 || index[f[1]] < 0 || index[f[2]] < 0) continue;
    out.triangles.push_back({index[f[0]], index[f[1]], index[f[2]]});
    out.triangles.push_back({count + index[f[0]], count + index[f[2]], count + index[f[1]]});
  }
  return out;
}

Eigen::Matrix3Xd sheet_normals(const std::vector<Eigen::Vector3i>& triangles,
                               const Eigen::Matrix3Xd& points) {
  Eigen::Matrix3Xd normals = Eigen::Matrix3Xd::Zero(3, points.cols());
  for (const auto& f : triangles) {
    const Eigen::Vector3d a = points.col(f[0]), b = points.col(f[1]), c = points.col(f[2]);
    const Eigen::Vector3d n = (b - a).cross(c - a);
    for (int k = 0; k < 3; ++k) normals.col(f[k]) += n;
  }
  for (Eigen::Index i = 0; i < normals.cols(); ++i) {
    const double len = normals.col(i).norm();
    if (len > 0.0) normals.col(i) /= len;
  }
  return normals;
}

namespace {

// A pose's linear part, its rotation alone (normals turn without the scale), its shift, and the
// cosine of the largest angle allowed between a point's turned normal and the surface's.
struct PosedPairing {
  PosedPairing(const Similarity& T, double max_normal_angle_deg)
      : R(T.topLeftCorner<3, 3>()),
        rot(R / std::cbrt(std::max(1e-12, R.determinant()))),
        shift(T.topRightCorner<3, 1>()),
        cos_normal(std::cos(max_normal_angle_deg * M_PI / 180.0)) {}
  Eigen::Vector3d moved(const Eigen::Vector3d& p) const { return R * p + shift; }
  bool agrees(const Eigen::Vector3d& normal, const Eigen::Vector3d& surface_normal) const {
    return surface_normal.dot(rot * normal) >= cos_normal;
  }
  Eigen::Matrix3d R, rot;
  Eigen::Vector3d shift;
  double cos_normal;
};

}  // namespace

SurfacePairs pair_with_surface(const Eigen::Matrix3Xd& points, const Eigen::Matrix3Xd& normals,
                               const std::vector<Eigen::Index>& which, const Similarity& T,
                               const SurfaceLocator& surface, double reach,
                               double max_normal_angle_deg) {
  const PosedPairing posed(T, max_normal_angle_deg);
  std::vector<char> ok(which.size(), 0);
  std::vector<Eigen::Vector3d> target(which.size()), normal(which.size());
  std::vector<double> dist(which.size());
  parallel_for(
      which.size(),
      [&](size_t begin, size_t end) {
        for (size_t k = begin; k < end; ++k) {
          const Eigen::Index i = which[k];
          const Eigen::Vector3d p = posed.moved(points.col(i));
          const auto c = surface.closest_within(p, reach);
          if (!c) continue;
          normal[k] = surface.face_normal(c->face);
          if (!posed.agrees(normals.col(i), normal[k])) continue;
          ok[k] = 1;
          target[k] = c->point;
          dist[k] = c->distance;
        }
      },
      128);
  SurfacePairs out;
  for (size_t k = 0; k < which.size(); ++k)
    if (ok[k]) {
      out.index.push_back(which[k]);
      out.target.push_back(target[k]);
      out.normal.push_back(normal[k]);
      out.distance.push_back(dist[k]);
    }
  return out;
}

namespace {

// The target's surface sampled at points with their normals, and a search tree over them:
// nearest-sample pairing costs a small share of a closest-triangle query within a wide reach,
// and sorting out the pose's starts needs only roughly where the bone is.
struct SampledTarget {
  SampledTarget(const SurfaceLocator& surface, std::vector<Eigen::Vector3d> at)
      : index(std::move(at)) {
    normal.reserve(index.size());
    for (const auto& p : index.points()) {
      const auto c = surface.closest_within(p, 5.0);
      normal.push_back(c ? surface.face_normal(c->face) : Eigen::Vector3d::Zero());
    }
  }
  PointIndex index;
  std::vector<Eigen::Vector3d> normal;
};

// Pairs as pair_with_surface's, with the nearest sample and its tangent plane standing for the
// surface (the distance is to that plane); one thread (the starts are shared out instead).
SurfacePairs pair_with_samples(const Eigen::Matrix3Xd& points, const Eigen::Matrix3Xd& normals,
                               const std::vector<Eigen::Index>& which, const Similarity& T,
                               const SampledTarget& target, double reach,
                               double max_normal_angle_deg) {
  const PosedPairing posed(T, max_normal_angle_deg);
  SurfacePairs out;
  if (target.index.size() == 0) return out;
  for (const Eigen::Index i : which) {
    const Eigen::Vector3d p = posed.moved(points.col(i));
    double d2 = 0.0;
    const int nearest = target.index.nearest(p, &d2);
    if (d2 > reach * reach) continue;
    const Eigen::Vector3d& n = target.normal[nearest];
    if (n.isZero() || !posed.agrees(normals.col(i), n)) continue;
    const Eigen::Vector3d& q = target.index.points()[nearest];
    out.index.push_back(i);
    out.target.push_back(q);
    out.normal.push_back(n);
    out.distance.push_back(std::abs((p - q).dot(n)));
  }
  return out;
}

// Trimmed similarity ICP from `T`; returns the transform and its residual. `pair(T, reach,
// angle)` gives the pairs of `which` moved by T.
template <typename Pairing>
AlignResult icp(const Eigen::Matrix3Xd& points, const std::vector<Eigen::Index>& which,
                Similarity T, const Pairing& pair, const AlignParams& params, int iterations) {
  AlignResult r;
  r.transform = T;
  for (int it = 0; it < iterations; ++it) {
    const SurfacePairs p = pair(T, params.max_distance_mm, params.max_normal_angle_deg);
    if (p.index.size() < 10) {
      r.rms_mm = std::numeric_limits<double>::infinity();
      r.used = 0.0;
      return r;
    }
    // Pairs further than three times the median distance (and 2 mm) are left out. A
    // point-to-plane step (linearised about the pairs' centroid): the points may slide along
    // the surface, so a smooth vault turns into place in a few rounds where point-to-point ICP
    // creeps.
    const double limit = std::max(2.0, 3.0 * median_of(p.distance));
    const Eigen::Matrix3d M = T.topLeftCorner<3, 3>();
    const Eigen::Vector3d shift = T.topRightCorner<3, 1>();
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    int used = 0;
    for (size_t k = 0; k < p.index.size(); ++k)
      if (p.distance[k] <= limit) centroid += M * points.col(p.index[k]) + shift, ++used;
    centroid /= std::max(1, used);
    const int unknowns = params.with_scale ? 7 : 6;
    Eigen::MatrixXd N = Eigen::MatrixXd::Zero(unknowns, unknowns);
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(unknowns);
    double sq = 0.0;
    for (size_t k = 0; k < p.index.size(); ++k) {
      if (p.distance[k] > limit) continue;
      const Eigen::Vector3d q = M * points.col(p.index[k]) + shift - centroid;
      const Eigen::Vector3d& n = p.normal[k];
      Eigen::VectorXd row(unknowns);
      row.head<3>() = q.cross(n);
      row.segment<3>(3) = n;
      if (params.with_scale) row(6) = q.dot(n);
      N += row * row.transpose();
      rhs -= row * (q + centroid - p.target[k]).dot(n);
      sq += p.distance[k] * p.distance[k];
    }
    r.rms_mm = std::sqrt(sq / std::max(1, used));
    r.used = static_cast<double>(used) / which.size();
    // Damped (a surface near a sphere hardly holds the turn about its centre) and bounded: at
    // most 0.2 rad, 10 mm and 5 % a round.
    const double damping = 1e-6 * N.trace() / unknowns;
    for (int k = 0; k < unknowns; ++k) N(k, k) += 0.01 * N(k, k) + damping;
    Eigen::VectorXd step = N.ldlt().solve(rhs);
    if (!step.allFinite()) break;
    const double turn_norm = step.head<3>().norm(), move_norm = step.segment<3>(3).norm();
    if (turn_norm > 0.2) step.head<3>() *= 0.2 / turn_norm;
    if (move_norm > 10.0) step.segment<3>(3) *= 10.0 / move_norm;
    if (params.with_scale) step(6) = std::clamp(step(6), -0.05, 0.05);
    const Eigen::Vector3d omega = step.head<3>();
    const double angle = omega.norm();
    const Eigen::Matrix3d turn = angle > 0.0
                                     ? Eigen::AngleAxisd(angle, omega / angle).toRotationMatrix()
                                     : Eigen::Matrix3d::Identity();
    const double grow = params.with_scale ? 1.0 + step(6) : 1.0;
    Similarity D = Similarity::Identity();  // about the centroid, then the shift
    D.topLeftCorner<3, 3>() = grow * turn;
    D.topRightCorner<3, 1>() = centroid - grow * turn * centroid + step.segment<3>(3);
    T = D * T;
    r.transform = T;
    // Settled: a round turns less than 2e-5 rad (about 2 µm at 100 mm from the centroid) and
    // moves less than a micrometre.
    if (angle < 2e-5 && step.segment<3>(3).norm() < 1e-3 &&
        (!params.with_scale || std::abs(step(6)) < 1e-5))
      break;
  }
  return r;
}

}  // namespace

AlignResult align_to_surface(const Eigen::Matrix3Xd& points, const Eigen::Matrix3Xd& normals,
                             const SurfaceLocator& target,
                             const std::vector<Eigen::Vector3d>& target_points,
                             const AlignParams& params, const Similarity* start,
                             const std::function<bool(Eigen::Index)>& usable) {
  std::vector<Eigen::Index> all;
  for (Eigen::Index i = 0; i < points.cols(); ++i)
    if (!usable || usable(i)) all.push_back(i);
  auto every = [](const std::vector<Eigen::Index>& from, size_t count) {
    std::vector<Eigen::Index> out;
    const size_t step = std::max<size_t>(1, from.size() / std::max<size_t>(1, count));
    for (size_t k = 0; k < from.size(); k += step) out.push_back(from[k]);
    return out;
  };
  const std::vector<Eigen::Index> fine = every(all, static_cast<size_t>(params.samples));
  auto on_surface = [&](const std::vector<Eigen::Index>& which) {
    return [&points, &normals, &target, &which](const Similarity& T, double reach, double angle) {
      return pair_with_surface(points, normals, which, T, target, reach, angle);
    };
  };
  if (start) return icp(points, fine, *start, on_surface(fine), params, params.iterations);

  std::vector<Eigen::Vector3d> mine;
  for (Eigen::Index i : every(all, 20000)) mine.push_back(points.col(i));
  const auto from = sphere_of(mine), to = sphere_of(target_points);
  Eigen::Vector3d c_from = Eigen::Vector3d::Zero(), c_to = Eigen::Vector3d::Zero();
  double scale = 1.0;
  if (from && to) {
    c_from = from->center;
    c_to = to->center;
    const double ratio = from->radius > 1e-6 ? to->radius / from->radius : 1.0;
    if (params.with_scale && std::isfinite(ratio)) scale = std::clamp(ratio, 0.7, 1.4);
  }
  // The starts are sorted out on 200 points, the best refined on 600.
  const std::vector<Eigen::Index> sparse = every(all, 200), coarse = every(all, 600);
  AlignParams loose = params;
  loose.max_distance_mm = std::max(params.max_distance_mm, 30.0);
  loose.with_scale = false;  // the spheres' ratio until the pose is found: free, ICP shrinks
  // Each start is judged by a truncated cost: the mean of min(d, 5 mm)² over the points, d the
  // distance to bone whose normal agrees (5 mm where there is none). A pose that pairs many
  // points loosely loses to one that lays most of them on the bone.
  constexpr double kCap = 5.0;
  auto cost_from = [&](const SurfacePairs& p, const std::vector<Eigen::Index>& which) {
    double cost = kCap * kCap * static_cast<double>(which.size() - p.index.size());
    for (double d : p.distance) cost += d * d;
    return cost / static_cast<double>(which.size());
  };
  auto cost_of = [&](const Similarity& T, const std::vector<Eigen::Index>& which) {
    return cost_from(
        pair_with_surface(points, normals, which, T, target, kCap, params.max_normal_angle_deg),
        which);
  };
  // Every start refined a little, the best four refined further: ICP turns a smooth vault
  // slowly, and a start 25° off needs a few dozen rounds to arrive.
  // The starts on both cores (each start's rounds are too small to share out), on the sampled
  // surface; the best four on the surface itself.
  const SampledTarget samples(target, target_points);
  auto on_samples = [&](const Similarity& T, double reach, double angle) {
    return pair_with_samples(points, normals, sparse, T, samples, reach, angle);
  };
  const std::vector<Eigen::Matrix3d> starts = start_rotations();
  std::vector<std::pair<double, AlignResult>> each(starts.size());
  parallel_for(
      starts.size(),
      [&](size_t begin, size_t end) {
        for (size_t k = begin; k < end; ++k) {
          Similarity T = Similarity::Identity();
          T.topLeftCorner<3, 3>() = scale * starts[k];
          T.topRightCorner<3, 1>() = c_to - scale * starts[k] * c_from;
          const AlignResult r = icp(points, sparse, T, on_samples, loose, 8);
          each[k] = {
              std::isfinite(r.rms_mm)
                  ? cost_from(on_samples(r.transform, kCap, params.max_normal_angle_deg), sparse)
                  : std::numeric_limits<double>::infinity(),
              r};
        }
      },
      1);
  std::vector<std::pair<double, AlignResult>> tried;
  for (const auto& e : each)
    if (std::isfinite(e.first)) tried.push_back(e);
  std::sort(tried.begin(), tried.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  AlignResult best;
  best.rms_mm = std::numeric_limits<double>::infinity();
  double best_cost = std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < std::min<size_t>(4, tried.size()); ++k) {
    const AlignResult r =
        icp(points, coarse, tried[k].second.transform, on_surface(coarse), loose, 30);
    if (!std::isfinite(r.rms_mm)) continue;
    const double cost = cost_of(r.transform, coarse);
    if (cost < best_cost) {
      best_cost = cost;
      best = r;
    }
  }
  if (!std::isfinite(best.rms_mm)) return best;
  return icp(points, fine, best.transform, on_surface(fine), params, params.iterations);
}

namespace {

// Gaussian smoothing of per-vertex displacements over one sheet's rest shape: sources thinned
// at a third of the width, each the mean of the displacements nearest it; a vertex takes the
// kernel-weighted mean of the sources near it (within three widths), shrunk where the data are
// few (a prior weight of a tenth of a source's).
class SheetSmoother {
 public:
  SheetSmoother(const Eigen::Matrix3Xd& rest, Eigen::Index begin, Eigen::Index end, double width)
      : begin_(begin) {
    std::vector<Eigen::Vector3d> pts;
    for (Eigen::Index i = begin; i < end; ++i) pts.push_back(rest.col(i));
    std::vector<Eigen::Vector3d> src;
    for (size_t k : thin_points(pts, width / 3.0)) src.push_back(pts[k]);
    sources_ = src.size();
    const PointIndex index(src);
    owner_.resize(pts.size());
    near_.resize(pts.size());
    for (size_t i = 0; i < pts.size(); ++i) {
      owner_[i] = index.nearest(pts[i]);
      for (int j : index.within_radius(pts[i], 3.0 * width)) {
        const double d2 = (pts[i] - src[j]).squaredNorm();
        near_[i].push_back({j, std::exp(-0.5 * d2 / (width * width))});
      }
    }
  }

  // `disp`/`weight` per vertex (weight 0: no datum); the smoothed displacement of each vertex
  // of the sheet into `out`.
  void smooth(const Eigen::Matrix3Xd& disp, const Eigen::VectorXd& weight,
              Eigen::Matrix3Xd& out) const {
    Eigen::Matrix3Xd sum = Eigen::Matrix3Xd::Zero(3, sources_);
    Eigen::VectorXd w = Eigen::VectorXd::Zero(sources_);
    for (size_t i = 0; i < owner_.size(); ++i) {
      const Eigen::Index v = begin_ + static_cast<Eigen::Index>(i);
      if (weight(v) <= 0.0) continue;
      sum.col(owner_[i]) += weight(v) * disp.col(v);
      w(owner_[i]) += weight(v);
    }
    for (size_t i = 0; i < owner_.size(); ++i) {
      Eigen::Vector3d s = Eigen::Vector3d::Zero();
      double ws = 0.0;
      for (const auto& [j, k] : near_[i]) {
        s += k * sum.col(j);
        ws += k * w(j);
      }
      out.col(begin_ + static_cast<Eigen::Index>(i)) = s / (ws + 0.1);
    }
  }

 private:
  Eigen::Index begin_;
  size_t sources_ = 0;
  std::vector<int> owner_;
  std::vector<std::vector<std::pair<int, double>>> near_;
};

}  // namespace

Correspondence correspond_skull(const ShapeTemplate& tmpl, const SkullMesh& skull,
                                const CorrespondParams& params) {
  Correspondence r;
  if (tmpl.points.cols() == 0 || skull.n_faces() == 0) {
    r.message = "nothing to correspond (an empty template or skull)";
    return r;
  }
  const SurfaceLocator bone(skull);
  const std::vector<Eigen::Vector3d> sample = vertex_sample(skull, 40000);
  const Eigen::Matrix3Xd rest_normals = sheet_normals(tmpl.triangles, tmpl.points);
  const AlignResult pose = align_to_surface(tmpl.points, rest_normals, bone, sample, params.align);
  if (!std::isfinite(pose.rms_mm) || pose.used < 0.3) {
    r.message = "the template could not be aligned with the skull (no pose pairs a third of it)";
    return r;
  }
  Eigen::Matrix3Xd x = apply_similarity(pose.transform, tmpl.points);
  const Eigen::Index n = x.cols(), outer = tmpl.outer_count;
  const double cos_normal = std::cos(params.max_normal_angle_deg * M_PI / 180.0);
  // The skull's sampled vertices with their normals, for the pairing back.
  const SkullMesh& m = skull;
  std::vector<Eigen::Vector3d> back_pts, back_nrm;
  {
    const std::vector<Eigen::Vector3d> normals = vertex_normals(m);
    const size_t step = std::max<size_t>(1, m.n_vertices() / 60000);
    for (size_t i = 0; i < m.n_vertices(); i += step) {
      back_pts.push_back(to_eigen(m.point(SkullMesh::VertexHandle(static_cast<int>(i)))));
      back_nrm.push_back(normals[i]);
    }
  }
  std::vector<Eigen::Index> all(n);
  std::iota(all.begin(), all.end(), Eigen::Index{0});
  for (double width : params.kernel_mm) {
    const SheetSmoother outer_s(tmpl.points, 0, outer, width),
        inner_s(tmpl.points, outer, n, width);
    for (int it = 0; it < params.iterations; ++it) {
      const Eigen::Matrix3Xd normals = sheet_normals(tmpl.triangles, x);
      Eigen::Matrix3Xd disp = Eigen::Matrix3Xd::Zero(3, n);
      Eigen::VectorXd weight = Eigen::VectorXd::Zero(n);
      const SurfacePairs fwd =
          pair_with_surface(x, normals, all, Similarity::Identity(), bone, params.max_distance_mm,
                            params.max_normal_angle_deg);
      for (size_t k = 0; k < fwd.index.size(); ++k) {
        disp.col(fwd.index[k]) += fwd.target[k] - x.col(fwd.index[k]);
        weight(fwd.index[k]) += 1.0;
      }
      // Back: each skull point near the template pulls its nearest vertex of the same side.
      std::vector<Eigen::Vector3d> xs(n);
      for (Eigen::Index i = 0; i < n; ++i) xs[i] = x.col(i);
      const PointIndex index(std::move(xs));
      for (size_t k = 0; k < back_pts.size(); ++k) {
        double d2 = 0.0;
        const int j = index.nearest(back_pts[k], &d2);
        if (d2 > params.max_distance_mm * params.max_distance_mm) continue;
        if (back_nrm[k].dot(normals.col(j)) < cos_normal) continue;
        // Along the vertex's normal only: skull points beyond the template's border would
        // otherwise stretch the sheet outward, and a vertex would leave its anatomy.
        disp.col(j) += (back_pts[k] - x.col(j)).dot(normals.col(j)) * normals.col(j);
        weight(j) += 1.0;
      }
      for (Eigen::Index i = 0; i < n; ++i)
        if (weight(i) > 0.0) disp.col(i) /= weight(i);
      Eigen::Matrix3Xd step(3, n);
      outer_s.smooth(disp, weight, step);
      inner_s.smooth(disp, weight, step);
      x += step;
    }
  }
  // How close the vertices came.
  double sq = 0.0;
  int near = 0, within = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto c = bone.closest_within(x.col(i), params.max_distance_mm);
    if (!c) continue;
    sq += c->distance * c->distance;
    ++within;
    if (c->distance <= 2.0) ++near;
  }
  r.rms_mm = std::sqrt(sq / std::max(1, within));
  r.matched = static_cast<double>(near) / n;
  r.points = std::move(x);
  r.status = Correspondence::Status::Corresponded;
  r.message = "template on the skull: " + std::to_string(static_cast<int>(100 * r.matched + 0.5)) +
              "% of its vertices within 2 mm of the bone";
  return r;
}

}  // namespace cranioplan
