#include "cranioplan/algorithms/geometry/self_intersections.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "cranioplan/model/parallel.h"

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
  // Cells of about two edge lengths, numbered from the mesh's lowest corner and packed 21 bits
  // an axis into one key (larger cells if the mesh spans more than 2²¹ of them: the count does
  // not depend on the cell size, only the time does).
  Eigen::Vector3d low = lo[0], high = hi[0];
  for (size_t i = 1; i < n; ++i) {
    low = low.cwiseMin(lo[i]);
    high = high.cwiseMax(hi[i]);
  }
  constexpr double kCells = double(1 << 21) - 2.0;
  const double cell =
      std::max({1e-6, 2.0 * edge_sum / static_cast<double>(n), (high - low).maxCoeff() / kCells});
  auto cell_of = [&](const Eigen::Vector3d& p) {
    return Eigen::Array3i(((p - low) / cell).array().floor().cast<int>());
  };
  auto key_of = [](int x, int y, int z) {
    return static_cast<uint64_t>(x) << 42 | static_cast<uint64_t>(y) << 21 |
           static_cast<uint64_t>(z);
  };
  // Every (cell, triangle) its box meets, sorted by cell: the triangles sharing a cell are
  // neighbours in the list.
  struct Entry {
    uint64_t cell;
    int triangle;
  };
  std::vector<Entry> entries;
  entries.reserve(2 * n);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Array3i a = cell_of(lo[i]), b = cell_of(hi[i]);
    for (int x = a[0]; x <= b[0]; ++x)
      for (int y = a[1]; y <= b[1]; ++y)
        for (int z = a[2]; z <= b[2]; ++z)
          entries.push_back({key_of(x, y, z), static_cast<int>(i)});
  }
  parallel_sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
    return a.cell != b.cell ? a.cell < b.cell : a.triangle < b.triangle;  // entries are distinct
  });
  std::vector<size_t> starts;
  for (size_t e = 0; e < entries.size(); ++e)
    if (e == 0 || entries[e].cell != entries[e - 1].cell) starts.push_back(e);
  starts.push_back(entries.size());
  const size_t groups = starts.size() - 1;
  // Each pair is tested once, in the cell holding the corner where their boxes start; the
  // cells on all threads, each thread's count added in thread order (an integer: the same sum).
  std::vector<long long> counts(groups, 0);
  parallel_for(
      groups,
      [&](size_t first, size_t last) {
        for (size_t g = first; g < last; ++g) {
          long long count = 0;
          for (size_t u = starts[g]; u < starts[g + 1]; ++u)
            for (size_t w = u + 1; w < starts[g + 1]; ++w) {
              const size_t i = static_cast<size_t>(entries[u].triangle),
                           j = static_cast<size_t>(entries[w].triangle);
              const Eigen::Array3i owner = cell_of(lo[i].cwiseMax(lo[j]));
              if (key_of(owner[0], owner[1], owner[2]) != entries[u].cell) continue;
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
                cross =
                    segment_crosses(V[ti[e]], V[ti[(e + 1) % 3]], V[tj[0]], V[tj[1]], V[tj[2]]) ||
                    segment_crosses(V[tj[e]], V[tj[(e + 1) % 3]], V[ti[0]], V[ti[1]], V[ti[2]]);
              count += cross;
            }
          counts[g] = count;
        }
      },
      64);
  long long count = 0;
  for (long long c : counts) count += c;
  return count;
}

}  // namespace cranioplan
