#include "cranioplan/algorithms/mesh_report.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <map>
#include <unordered_map>

#include "cranioplan/algorithms/mesh_components.h"

namespace cranioplan {

MeshReport report_mesh(const SkullMesh& mesh) {
  MeshReport r;
  TriangleSoup soup = to_soup(mesh);
  r.vertices = static_cast<long long>(soup.vertices.size());
  r.triangles = static_cast<long long>(soup.triangles.size());
  if (soup.vertices.empty()) return r;
  r.bbox_min = r.bbox_max = soup.vertices[0];
  for (const auto& p : soup.vertices) {
    r.bbox_min = r.bbox_min.cwiseMin(p);
    r.bbox_max = r.bbox_max.cwiseMax(p);
  }
  for (const auto& t : soup.triangles) {
    const auto &a = soup.vertices[t[0]], &b = soup.vertices[t[1]], &c = soup.vertices[t[2]];
    r.area_mm2 += 0.5 * (b - a).cross(c - a).norm();
  }
  r.volume_mm3 = signed_volume(soup);

  // Weld identical positions, then count triangles per undirected edge.
  std::map<std::array<double, 3>, int> weld;
  std::vector<int> id(soup.vertices.size());
  for (size_t i = 0; i < soup.vertices.size(); ++i) {
    const auto& p = soup.vertices[i];
    id[i] = weld.emplace(std::array<double, 3>{p.x(), p.y(), p.z()}, static_cast<int>(weld.size()))
                .first->second;
  }
  std::unordered_map<unsigned long long, int> edge_count;
  edge_count.reserve(soup.triangles.size() * 2);
  for (auto& t : soup.triangles) {
    for (int k = 0; k < 3; ++k) t[k] = id[t[k]];
    for (int k = 0; k < 3; ++k) {
      const unsigned long long a = static_cast<unsigned>(t[k]),
                               b = static_cast<unsigned>(t[(k + 1) % 3]);
      ++edge_count[std::min(a, b) << 32 | std::max(a, b)];
    }
  }
  for (const auto& [edge, count] : edge_count) {
    if (count == 1) ++r.boundary_edges;
    if (count > 2) ++r.nonmanifold_edges;
  }
  soup.vertices.resize(weld.size());
  for (const auto& [p, i] : weld) soup.vertices[i] = {p[0], p[1], p[2]};
  r.pieces = static_cast<long long>(soup_components(soup).sizes.size());
  r.watertight = r.boundary_edges == 0 && r.nonmanifold_edges == 0;
  return r;
}

}  // namespace cranioplan
