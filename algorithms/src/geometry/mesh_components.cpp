#include "cranioplan/algorithms/geometry/mesh_components.h"

#include <algorithm>
#include <numeric>

namespace cranioplan {
namespace {
int find_root(std::vector<int>& parent, int x) {
  while (parent[x] != x) {
    parent[x] = parent[parent[x]];
    x = parent[x];
  }
  return x;
}
}  // namespace

SoupComponents soup_components(const TriangleSoup& soup) {
  std::vector<int> parent(soup.vertices.size());
  std::iota(parent.begin(), parent.end(), 0);
  for (const auto& t : soup.triangles)
    for (int k = 1; k < 3; ++k) {
      const int a = find_root(parent, t[0]), b = find_root(parent, t[k]);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  std::vector<int> root_label(soup.vertices.size(), -1);
  std::vector<long long> counts;
  std::vector<int> raw(soup.triangles.size());
  for (size_t i = 0; i < soup.triangles.size(); ++i) {
    const int r = find_root(parent, soup.triangles[i][0]);
    if (root_label[r] < 0) {
      root_label[r] = static_cast<int>(counts.size());
      counts.push_back(0);
    }
    raw[i] = root_label[r];
    ++counts[raw[i]];
  }
  std::vector<int> order(counts.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return counts[a] > counts[b]; });
  std::vector<int> rank(counts.size());
  SoupComponents out;
  for (size_t r = 0; r < order.size(); ++r) {
    rank[order[r]] = static_cast<int>(r);
    out.sizes.push_back(counts[order[r]]);
  }
  out.label.resize(raw.size());
  for (size_t i = 0; i < raw.size(); ++i) out.label[i] = rank[raw[i]];
  return out;
}

TriangleSoup keep_largest_pieces(const TriangleSoup& soup, const SoupComponents& comps,
                                 int keep_count) {
  std::vector<bool> keep(comps.sizes.size(), false);
  for (size_t c = 0; c < keep.size() && static_cast<int>(c) < keep_count; ++c) keep[c] = true;
  return keep_pieces(soup, comps, keep);
}

TriangleSoup keep_pieces(const TriangleSoup& soup, const SoupComponents& comps,
                         const std::vector<bool>& keep) {
  TriangleSoup out;
  std::vector<int> remap(soup.vertices.size(), -1);
  for (size_t i = 0; i < soup.triangles.size(); ++i) {
    if (!keep[static_cast<size_t>(comps.label[i])]) continue;
    Eigen::Vector3i t;
    for (int k = 0; k < 3; ++k) {
      int& m = remap[soup.triangles[i][k]];
      if (m < 0) {
        m = static_cast<int>(out.vertices.size());
        out.vertices.push_back(soup.vertices[soup.triangles[i][k]]);
      }
      t[k] = m;
    }
    out.triangles.push_back(t);
  }
  return out;
}

std::vector<PieceBox> piece_boxes(const TriangleSoup& soup, const SoupComponents& comps) {
  std::vector<PieceBox> boxes(comps.sizes.size());
  for (size_t i = 0; i < soup.triangles.size(); ++i) {
    PieceBox& b = boxes[static_cast<size_t>(comps.label[i])];
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d& p = soup.vertices[soup.triangles[i][k]];
      b.lo = b.lo.cwiseMin(p);
      b.hi = b.hi.cwiseMax(p);
    }
  }
  return boxes;
}

double PieceBox::gap_to(const PieceBox& o) const {
  const Eigen::Vector3d g = (o.lo - hi).cwiseMax(lo - o.hi).cwiseMax(Eigen::Vector3d::Zero());
  return g.norm();
}

}  // namespace cranioplan
