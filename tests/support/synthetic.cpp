#include "support/synthetic.h"

#include <Eigen/Geometry>
#include <cmath>
#include <map>

namespace cranioplan::test {
namespace {

// Icosphere with vertices symmetric under x ↦ −x.
TriangleSoup icosphere(int subdivisions) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  TriangleSoup s;
  s.vertices = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (auto& v : s.vertices) v.normalize();
  s.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                 {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                 {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                 {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int level = 0; level < subdivisions; ++level) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      s.vertices.push_back((s.vertices[a] + s.vertices[b]).normalized());
      const int id = static_cast<int>(s.vertices.size()) - 1;
      mid[key] = id;
      return id;
    };
    std::vector<Eigen::Vector3i> next;
    for (const auto& tr : s.triangles) {
      const int a = midpoint(tr[0], tr[1]), b = midpoint(tr[1], tr[2]), c = midpoint(tr[2], tr[0]);
      next.emplace_back(tr[0], a, c);
      next.emplace_back(tr[1], b, a);
      next.emplace_back(tr[2], c, b);
      next.emplace_back(a, b, c);
    }
    s.triangles = std::move(next);
  }
  return s;
}

// Radius of the head along unit direction u; even in u.x, so the head is symmetric in x.
Eigen::Vector3d head_point(const Eigen::Vector3d& u) {
  const double x2 = u.x() * u.x();
  double r = 1.0 + 0.12 * u.y() + 0.08 * u.z() * u.z() - 0.06 * u.y() * u.z() + 0.05 * x2 * u.z();
  // Nose ridge at the front, on the midline, slightly below the equator.
  const double front = std::max(0.0, u.y());
  r += 0.10 * std::exp(-(x2 / 0.02) - std::pow(u.z() + 0.15, 2) / 0.05) * std::pow(front, 4);
  // Flattened back of the head.
  if (u.y() < -0.6) r -= 0.2 * std::pow(-u.y() - 0.6, 2);
  return Eigen::Vector3d(70.0 * u.x(), 85.0 * u.y(), 72.0 * u.z()) * r;
}

}  // namespace

SkullMesh make_symmetric_head(int subdivisions) {
  TriangleSoup s = icosphere(subdivisions);
  for (auto& v : s.vertices) v = head_point(v);
  return build_mesh(s);
}

Landmarks head_landmarks() {
  Landmarks lm;
  lm.nasion = head_point(Eigen::Vector3d(0, 0.95, 0.05).normalized());
  lm.orbit_left = Eigen::Vector3d(-32, 78, 5);
  lm.orbit_right = Eigen::Vector3d(32, 78, 5);
  return lm;
}

SkullMesh cut_hole(const SkullMesh& mesh, const Eigen::Vector3d& center, double radius) {
  TriangleSoup s = to_soup(mesh);
  std::vector<Eigen::Vector3i> kept;
  for (const auto& t : s.triangles) {
    const Eigen::Vector3d c = (s.vertices[t[0]] + s.vertices[t[1]] + s.vertices[t[2]]) / 3.0;
    if ((c - center).norm() > radius) kept.push_back(t);
  }
  s.triangles = kept;
  return build_mesh(s);
}

SkullMesh transformed(const SkullMesh& mesh, const RigidTransform& t) {
  SkullMesh out = mesh;
  for (auto vh : out.vertices()) out.set_point(vh, to_point(t.apply(to_eigen(out.point(vh)))));
  return out;
}

Landmarks transformed(const Landmarks& lm, const RigidTransform& t) {
  Landmarks out = lm;
  if (out.nasion) out.nasion = t.apply(*out.nasion);
  if (out.orbit_left) out.orbit_left = t.apply(*out.orbit_left);
  if (out.orbit_right) out.orbit_right = t.apply(*out.orbit_right);
  for (auto& p : out.midline) p = t.apply(p);
  return out;
}

Plane transformed(const Plane& p, const RigidTransform& t) {
  return Plane::through(t.apply(p.normal * p.offset), t.apply_direction(p.normal));
}

Volume make_ball_volume(const Eigen::Vector3d& center_world, double radius, int n, double spacing,
                        bool as_ct) {
  Volume v;
  v.dims = {n, n, n};
  v.directions = Eigen::Matrix3d::Identity() * spacing;
  v.origin = center_world - Eigen::Vector3d::Constant(spacing * (n - 1) / 2.0);
  v.kind = as_ct ? VolumeKind::CT : VolumeKind::Mask;
  v.data.resize(v.size());
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const bool in = (v.world(Eigen::Vector3d(i, j, k)) - center_world).norm() <= radius;
        v.data[v.index(i, j, k)] = as_ct ? (in ? 1000.0f : -1000.0f) : (in ? 1.0f : 0.0f);
      }
  return v;
}

}  // namespace cranioplan::test
