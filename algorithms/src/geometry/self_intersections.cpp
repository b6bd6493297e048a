#include "cranioplan/algorithms/geometry/self_intersections.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace cranioplan {
namespace {

// Does the open segment p→q cross the interior of triangle (a, b, c)? (Möller–Trumbore)
bool segment_crosses(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& a,
                     const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d dir = q - p, e1 = b - a, e2 = c - a;
  const Eigen::Vector3d h = dir.cross(e2);
  const double det = e1.dot(h);
  if (std::abs(det) < 1e-14 * e1.norm() * e2.norm() * dir.norm()) return false;
  const Eigen::Vector3d s = p - a;
  const double u = s.dot(h) / det;
  if (u <= 0 || u >= 1) return false;
  const Eigen::Vector3d qv = s.cross(e1);
  const double v = dir.dot(qv) / det;
  if (v <= 0 || u + v >= 1) return false;
  const double t = e2.dot(qv) / det;
  return t > 0 && t < 1;
}

}  // namespace

long long count_self_intersections(const SkullMesh& mesh) {
  const TriangleSoup soup = to_soup(mesh);
  const size_t n = soup.triangles.size();
  if (n < 2) return 0;
  std::vector<Eigen::Vector3d> lo(n), hi(n);
  double edge_sum = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const auto& t = soup.triangles[i];
    lo[i] = soup.vertices[t[0]].cwiseMin(soup.vertices[t[1]]).cwiseMin(soup.vertices[t[2]]);
    hi[i] = soup.vertices[t[0]].cwiseMax(soup.vertices[t[1]]).cwiseMax(soup.vertices[t[2]]);
    edge_sum += (soup.vertices[t[0]] - soup.vertices[t[1]]).norm();
  }
  const double cell = std::max(1e-6, 2.0 * edge_sum / static_cast<double>(n));
  auto key = [](long long x, long long y, long long z) {
    return static_cast<unsigned long long>((x * 73856093LL) ^ (y * 19349663LL) ^ (z * 83492791LL));
  };
  std::unordered_multimap<unsigned long long, int> cells;
  auto cell_of = [&](const Eigen::Vector3d& p) {
    return Eigen::Array3i((p / cell).array().floor().cast<int>());
  };
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Array3i a = cell_of(lo[i]), b = cell_of(hi[i]);
    for (int x = a[0]; x <= b[0]; ++x)
      for (int y = a[1]; y <= b[1]; ++y)
        for (int z = a[2]; z <= b[2]; ++z) cells.emplace(key(x, y, z), static_cast<int>(i));
  }
  long long count = 0;
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Array3i a = cell_of(lo[i]), b = cell_of(hi[i]);
    for (int x = a[0]; x <= b[0]; ++x)
      for (int y = a[1]; y <= b[1]; ++y)
        for (int z = a[2]; z <= b[2]; ++z) {
          auto range = cells.equal_range(key(x, y, z));
          for (auto it = range.first; it != range.second; ++it) {
            const size_t j = static_cast<size_t>(it->second);
            if (j <= i) continue;
            // Test each pair once: in the cell holding the corner where their boxes start.
            const Eigen::Array3i owner = cell_of(lo[i].cwiseMax(lo[j]));
            if (owner[0] != x || owner[1] != y || owner[2] != z) continue;
            if ((lo[i].array() > hi[j].array()).any() || (lo[j].array() > hi[i].array()).any())
              continue;
            const auto &ti = soup.triangles[i], &tj = soup.triangles[j];
            bool shared = false;
            for (int p = 0; p < 3; ++p)
              for (int q = 0; q < 3; ++q) shared |= ti[p] == tj[q];
            if (shared) continue;
            const auto& V = soup.vertices;
            bool cross = false;
            for (int e = 0; e < 3 && !cross; ++e)
              cross = segment_crosses(V[ti[e]], V[ti[(e + 1) % 3]], V[tj[0]], V[tj[1]], V[tj[2]]) ||
                      segment_crosses(V[tj[e]], V[tj[(e + 1) % 3]], V[ti[0]], V[ti[1]], V[ti[2]]);
            count += cross;
          }
        }
  }
  return count;
}

}  // namespace cranioplan
