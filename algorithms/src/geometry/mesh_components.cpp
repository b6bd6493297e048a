#include "cranioplan/algorithms/geometry/mesh_components.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cstdint>
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

namespace {
// One id per position (the smallest index among the vertices at it, in sorted order): files
// that list a vertex once per face still share corners.
std::vector<int> position_ids(const TriangleSoup& soup) {
  std::vector<int> order(soup.vertices.size());
  std::iota(order.begin(), order.end(), 0);
  auto less = [&](int a, int b) {
    const Eigen::Vector3d &p = soup.vertices[a], &q = soup.vertices[b];
    return std::lexicographical_compare(p.data(), p.data() + 3, q.data(), q.data() + 3);
  };
  std::sort(order.begin(), order.end(), less);
  std::vector<int> id(soup.vertices.size());
  for (size_t k = 0; k < order.size(); ++k)
    id[order[k]] = k > 0 && !less(order[k - 1], order[k]) ? id[order[k - 1]] : static_cast<int>(k);
  return id;
}
}  // namespace

long long drop_repeated_triangles(TriangleSoup& soup) {
  const std::vector<int> id = position_ids(soup);
  std::vector<std::pair<std::array<int, 3>, uint32_t>> keys(soup.triangles.size());
  for (size_t t = 0; t < soup.triangles.size(); ++t) {
    std::array<int, 3> k{id[soup.triangles[t][0]], id[soup.triangles[t][1]],
                         id[soup.triangles[t][2]]};
    std::sort(k.begin(), k.end());
    keys[t] = {k, static_cast<uint32_t>(t)};
  }
  std::sort(keys.begin(), keys.end());
  std::vector<char> keep(soup.triangles.size(), 1);
  long long dropped = 0;
  for (size_t i = 1; i < keys.size(); ++i)
    // A repeat of the triangle before it (the first in the file's order is kept); triangles
    // with a repeated corner are left to the mesh builder, which drops them as degenerate.
    if (keys[i].first == keys[i - 1].first && keys[i].first[0] != keys[i].first[1] &&
        keys[i].first[1] != keys[i].first[2]) {
      keep[keys[i].second] = 0;
      ++dropped;
    }
  if (dropped == 0) return 0;
  size_t w = 0;
  for (size_t t = 0; t < soup.triangles.size(); ++t)
    if (keep[t]) soup.triangles[w++] = soup.triangles[t];
  soup.triangles.resize(w);
  return dropped;
}

SoupOrientation orient_consistently(TriangleSoup& soup) {
  SoupOrientation out;
  const size_t nt = soup.triangles.size();
  const std::vector<int> id = position_ids(soup);
  // Every triangle's edges, bucketed by their smaller position id (a counting sort); in a
  // bucket, the larger id, the triangle, and whether it runs the edge from smaller to larger.
  struct Use {
    int other;
    uint32_t tri;
    bool forward;
  };
  std::vector<int> first(soup.vertices.size() + 1, 0);
  for (const auto& f : soup.triangles)
    for (int k = 0; k < 3; ++k) {
      const int a = id[f[k]], b = id[f[(k + 1) % 3]];
      if (a != b) ++first[std::min(a, b) + 1];
    }
  std::partial_sum(first.begin(), first.end(), first.begin());
  std::vector<Use> uses(static_cast<size_t>(first.back()));
  {
    std::vector<int> fill(first.begin(), first.end() - 1);
    for (size_t t = 0; t < nt; ++t)
      for (int k = 0; k < 3; ++k) {
        const int a = id[soup.triangles[t][k]], b = id[soup.triangles[t][(k + 1) % 3]];
        if (a != b)
          uses[fill[std::min(a, b)]++] = {std::max(a, b), static_cast<uint32_t>(t), a < b};
      }
  }
  // Each triangle's neighbours over its edges of exactly two triangles: the neighbour, and 1
  // when both run the edge alike (2 * neighbour + alike; -1 for none).
  std::vector<int64_t> links(3 * nt, -1);
  std::vector<uint8_t> link_count(nt, 0);
  auto link = [&](uint32_t t, uint32_t u, bool alike) {
    if (link_count[t] < 3) links[3 * t + link_count[t]++] = 2 * static_cast<int64_t>(u) + alike;
  };
  for (size_t v = 0; v + 1 < first.size(); ++v) {
    const auto lo = uses.begin() + first[v], hi = uses.begin() + first[v + 1];
    std::sort(lo, hi, [](const Use& x, const Use& y) {
      return x.other != y.other ? x.other < y.other : x.tri < y.tri;
    });
    for (auto i = lo; i != hi;) {
      auto j = i;
      while (j != hi && j->other == i->other) ++j;
      if (j - i == 2 && i->tri != (i + 1)->tri) {
        const bool alike = i->forward == (i + 1)->forward;
        link(i->tri, (i + 1)->tri, alike);
        link((i + 1)->tri, i->tri, alike);
      }
      i = j;
    }
  }
  auto area = [&](size_t t) {
    const Eigen::Vector3i& f = soup.triangles[t];
    return (soup.vertices[f[1]] - soup.vertices[f[0]])
        .cross(soup.vertices[f[2]] - soup.vertices[f[0]])
        .norm();
  };
  // Each patch from its first triangle: `flip` relative to it, then the smaller part turned.
  std::vector<int8_t> flip(nt, -1);
  std::vector<char> done(nt, 0);
  std::vector<uint32_t> patch, stack;
  for (size_t seed = 0; seed < nt; ++seed) {
    if (flip[seed] >= 0) continue;
    patch.clear();
    stack.assign(1, static_cast<uint32_t>(seed));
    flip[seed] = 0;
    std::array<double, 2> by_flip{0.0, 0.0};
    while (!stack.empty()) {
      const uint32_t t = stack.back();
      stack.pop_back();
      patch.push_back(t);
      done[t] = 1;
      by_flip[flip[t]] += area(t);
      for (int k = 0; k < link_count[t]; ++k) {
        const uint32_t other = static_cast<uint32_t>(links[3 * t + k] / 2);
        const int8_t want = static_cast<int8_t>(flip[t] ^ (links[3 * t + k] & 1));
        if (flip[other] < 0) {
          flip[other] = want;
          stack.push_back(other);
        } else if (flip[other] != want && done[other]) {
          ++out.conflicts;  // counted from the edge's second triangle only
        }
      }
    }
    const int8_t turn = by_flip[1] > by_flip[0] ? 0 : 1;
    for (uint32_t t : patch)
      if (flip[t] == turn) {
        std::swap(soup.triangles[t][1], soup.triangles[t][2]);
        ++out.triangles_turned;
      }
    // The turned triangles' own patches, for the report.
    for (uint32_t t : patch) flip[t] = flip[t] == turn ? 2 : 3;
    for (uint32_t t : patch) {
      if (flip[t] != 2) continue;
      ++out.patches_turned;
      stack.assign(1, t);
      flip[t] = 3;
      while (!stack.empty()) {
        const uint32_t u = stack.back();
        stack.pop_back();
        for (int k = 0; k < link_count[u]; ++k) {
          const uint32_t other = static_cast<uint32_t>(links[3 * u + k] / 2);
          if (flip[other] == 2) {
            flip[other] = 3;
            stack.push_back(other);
          }
        }
      }
    }
  }
  return out;
}

}  // namespace cranioplan
