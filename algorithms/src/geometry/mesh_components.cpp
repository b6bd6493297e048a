#include "cranioplan/algorithms/geometry/mesh_components.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cstdint>
#include <numeric>
#include <unordered_map>

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
// One id per position (the rank, in lexicographic order, of the first vertex there): files
// that list a vertex once per face still share corners.
std::vector<int> position_ids(const TriangleSoup& soup) {
  struct Key {
    std::array<double, 3> p;
    int index;
  };
  std::vector<Key> keys(soup.vertices.size());
  for (size_t i = 0; i < keys.size(); ++i)
    keys[i] = {{soup.vertices[i].x(), soup.vertices[i].y(), soup.vertices[i].z()},
               static_cast<int>(i)};
  std::sort(keys.begin(), keys.end(), [](const Key& a, const Key& b) { return a.p < b.p; });
  std::vector<int> id(soup.vertices.size());
  for (size_t k = 0; k < keys.size(); ++k)
    id[keys[k].index] =
        k > 0 && keys[k - 1].p == keys[k].p ? id[keys[k - 1].index] : static_cast<int>(k);
  return id;
}

// Every triangle's edges, bucketed by their smaller position id (a counting sort) and sorted
// in each bucket by the larger: the larger id, and the triangle with whether it runs the edge
// from the smaller id to the larger (2 * triangle + forward; eight bytes a use, as the uses
// are scattered into their buckets).
struct EdgeUse {
  int other;
  uint32_t tri_forward;
  uint32_t tri() const { return tri_forward >> 1; }
  bool forward() const { return tri_forward & 1u; }
};
struct EdgeUses {
  std::vector<int> first;  ///< bucket v is uses[first[v], first[v + 1])
  std::vector<EdgeUse> uses;
};
EdgeUses edge_uses(const TriangleSoup& soup, const std::vector<int>& id) {
  EdgeUses e;
  e.first.assign(soup.vertices.size() + 1, 0);
  for (const auto& f : soup.triangles)
    for (int k = 0; k < 3; ++k) {
      const int a = id[f[k]], b = id[f[(k + 1) % 3]];
      if (a != b) ++e.first[std::min(a, b) + 1];
    }
  std::partial_sum(e.first.begin(), e.first.end(), e.first.begin());
  e.uses.resize(static_cast<size_t>(e.first.back()));
  std::vector<int> fill(e.first.begin(), e.first.end() - 1);
  for (size_t t = 0; t < soup.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int a = id[soup.triangles[t][k]], b = id[soup.triangles[t][(k + 1) % 3]];
      if (a != b)
        e.uses[fill[std::min(a, b)]++] = {std::max(a, b),
                                          2u * static_cast<uint32_t>(t) + (a < b ? 1u : 0u)};
    }
  for (size_t v = 0; v + 1 < e.first.size(); ++v)
    std::sort(e.uses.begin() + e.first[v], e.uses.begin() + e.first[v + 1],
              [](const EdgeUse& x, const EdgeUse& y) {
                return x.other != y.other ? x.other < y.other : x.tri_forward < y.tri_forward;
              });
  return e;
}

// Calls f(lo, begin, end) for each group of uses of one undirected edge (lo: its smaller id).
template <class F>
void for_each_edge(const EdgeUses& e, F&& f) {
  for (size_t v = 0; v + 1 < e.first.size(); ++v) {
    const EdgeUse* hi = e.uses.data() + e.first[v + 1];
    for (const EdgeUse* i = e.uses.data() + e.first[v]; i != hi;) {
      const EdgeUse* j = i;
      while (j != hi && j->other == i->other) ++j;
      f(static_cast<int>(v), i, j);
      i = j;
    }
  }
}

long long drop_repeated(TriangleSoup& soup, const std::vector<int>& id) {
  // Triangles by their corners' position ids in order (a <= b <= c): counted out by a, each
  // bucket (a few triangles) sorted by b and c, and then by the triangle's place in the soup.
  const size_t nt = soup.triangles.size();
  std::vector<std::array<int, 3>> sorted(nt);
  std::vector<int> first(soup.vertices.size() + 1, 0);
  for (size_t t = 0; t < nt; ++t) {
    std::array<int, 3>& k = sorted[t];
    k = {id[soup.triangles[t][0]], id[soup.triangles[t][1]], id[soup.triangles[t][2]]};
    std::sort(k.begin(), k.end());
    ++first[k[0] + 1];
  }
  std::partial_sum(first.begin(), first.end(), first.begin());
  std::vector<std::pair<uint64_t, uint32_t>> items(nt);  // (b << 32 | c, triangle)
  {
    std::vector<int> fill(first.begin(), first.end() - 1);
    for (size_t t = 0; t < nt; ++t)
      items[fill[sorted[t][0]]++] = {
          (static_cast<uint64_t>(sorted[t][1]) << 32) | static_cast<uint32_t>(sorted[t][2]),
          static_cast<uint32_t>(t)};
  }
  std::vector<char> keep(nt, 1);
  long long dropped = 0;
  for (size_t v = 0; v + 1 < first.size(); ++v) {
    if (first[v + 1] - first[v] < 2) continue;
    const auto lo = items.begin() + first[v], hi = items.begin() + first[v + 1];
    std::sort(lo, hi);
    for (auto i = lo + 1; i != hi; ++i) {
      // A repeat of the triangle before it (the first in the soup's order is kept); triangles
      // with a repeated corner are left to the mesh builder, which drops them as degenerate.
      const std::array<int, 3>& k = sorted[i->second];
      if (i->first == (i - 1)->first && k[0] != k[1] && k[1] != k[2]) {
        keep[i->second] = 0;
        ++dropped;
      }
    }
  }
  if (dropped == 0) return 0;
  size_t w = 0;
  for (size_t t = 0; t < nt; ++t)
    if (keep[t]) soup.triangles[w++] = soup.triangles[t];
  soup.triangles.resize(w);
  return dropped;
}

SoupOrientation orient(TriangleSoup& soup, const EdgeUses& uses) {
  SoupOrientation out;
  const size_t nt = soup.triangles.size();
  // Each triangle's neighbours over its edges of exactly two triangles: the neighbour, and 1
  // when both run the edge alike (2 * neighbour + alike; link_count of them).
  std::vector<uint32_t> links(3 * nt, 0);
  std::vector<uint8_t> link_count(nt, 0);
  auto link = [&](uint32_t t, uint32_t u, bool alike) {
    if (link_count[t] < 3) links[3 * t + link_count[t]++] = 2u * u + (alike ? 1u : 0u);
  };
  for_each_edge(uses, [&](int, const EdgeUse* i, const EdgeUse* j) {
    if (j - i == 2 && i->tri() != (i + 1)->tri()) {
      const bool alike = i->forward() == (i + 1)->forward();
      link(i->tri(), (i + 1)->tri(), alike);
      link((i + 1)->tri(), i->tri(), alike);
    }
  });
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
        const uint32_t other = links[3 * t + k] / 2;
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
          const uint32_t other = links[3 * u + k] / 2;
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

// An open edge (used by one triangle), as its triangle runs it.
struct OpenEdge {
  int from, to;  // vertex indices
  int to_id;
  uint32_t tri;
};

// The open edges, and from each corner (by position id) the open edge that leaves it, -2 where
// several do (holes that touch there).
struct OpenEdges {
  std::vector<OpenEdge> edges;
  std::vector<long> leaving;
};

OpenEdges open_edges(const TriangleSoup& soup, const std::vector<int>& id, const EdgeUses& uses) {
  OpenEdges out;
  out.leaving.assign(soup.vertices.size(), -1);
  for_each_edge(uses, [&](int lo, const EdgeUse* i, const EdgeUse* j) {
    if (j - i != 1) return;
    // As the triangle runs it now (orient may have turned it since the uses were listed).
    const Eigen::Vector3i& t = soup.triangles[i->tri()];
    int k = 0;
    while (k < 2 && std::minmax(id[t[k]], id[t[(k + 1) % 3]]) != std::minmax(lo, i->other)) ++k;
    const int from = t[k], to = t[(k + 1) % 3];
    long& slot = out.leaving[id[from]];
    slot = slot == -1 ? static_cast<long>(out.edges.size()) : -2;
    out.edges.push_back({from, to, id[to], i->tri()});
  });
  return out;
}

// Where two holes touch at a corner (two lost triangles sharing a vertex), two open edges leave
// it. Around the corner lie hole, fan of triangles, hole, fan: turning from the edge that
// arrived through its own fan (across shared edges) reaches the edge that leaves into the other
// hole, so the hole goes on along the other. More than two holes at a corner, or a fan that
// cannot be turned through (an edge of three triangles, patches wound against each other), are
// not followed.
class CornerTurns {
 public:
  CornerTurns(const TriangleSoup& soup, const std::vector<int>& id, const OpenEdges& open,
              bool through_corners)
      : soup_(soup), id_(id), open_(open.edges) {
    for (size_t e = 0; e < open_.size(); ++e)
      if (open.leaving[id[open_[e].from]] == -2)
        leaving_at_[id[open_[e].from]].push_back(static_cast<long>(e));
    if (!through_corners) leaving_at_.clear();
    if (!leaving_at_.empty())
      for (size_t t = 0; t < soup.triangles.size(); ++t)
        for (int k = 0; k < 3; ++k)
          if (const auto at = leaving_at_.find(id[soup.triangles[t][k]]); at != leaving_at_.end())
            fan_at_[at->first].push_back(static_cast<uint32_t>(t));
  }

  // The open edge the hole goes on along after `arrived`, at a corner two holes touch; -1 where
  // the way is not clear.
  long next(long arrived) {
    const int p = open_[arrived].to_id;
    const std::vector<uint32_t>& fan = fan_at_[p];
    const auto at = leaving_at_.find(p);
    if (at == leaving_at_.end() || at->second.size() != 2) return -1;
    const std::vector<long>& leave = at->second;
    uint32_t t = open_[arrived].tri;
    for (size_t step = 0; step <= fan.size(); ++step) {
      const int k = corner_of(t, p);
      if (k < 0 || k > 2) return -1;
      const int after = id_[soup_.triangles[t][(k + 1) % 3]];
      for (int i = 0; i < 2; ++i)
        if (open_[leave[i]].tri == t && open_[leave[i]].to_id == after) return leave[1 - i];
      // The triangle across the edge from p to `after` runs it the other way.
      long across = -1;
      for (uint32_t s : fan) {
        const int ks = s == t ? -1 : corner_of(s, p);
        if (ks < 0 || ks > 2 || id_[soup_.triangles[s][(ks + 2) % 3]] != after) continue;
        if (across >= 0) return -1;  // an edge of more than two triangles
        across = s;
      }
      if (across < 0) return -1;
      t = static_cast<uint32_t>(across);
    }
    return -1;
  }

 private:
  int corner_of(uint32_t t, int p) const {
    const Eigen::Vector3i& f = soup_.triangles[t];
    int k = -1;
    for (int c = 0; c < 3; ++c)
      if (id_[f[c]] == p) k = k < 0 ? c : 3;  // 3: the corner twice, a degenerate triangle
    return k;
  }

  const TriangleSoup& soup_;
  const std::vector<int>& id_;
  const std::vector<OpenEdge>& open_;
  std::unordered_map<int, std::vector<long>> leaving_at_;
  std::unordered_map<int, std::vector<uint32_t>> fan_at_;
};

// A chain of open edges: a closed loop, or a part where the way round a corner is not clear (an
// edge of three triangles there, or patches wound against each other).
struct Chain {
  std::vector<int> corners;
  double length = 0.0;
  bool loop = true;
};

std::vector<Chain> open_chains(const TriangleSoup& soup, const OpenEdges& open,
                               CornerTurns& turns) {
  const std::vector<OpenEdge>& edges = open.edges;
  std::vector<char> used(edges.size(), 0);
  std::vector<Chain> chains;
  for (size_t start = 0; start < edges.size(); ++start) {
    if (used[start]) continue;
    Chain c;
    for (long e = static_cast<long>(start);;) {
      used[e] = 1;
      c.corners.push_back(edges[e].from);
      c.length += (soup.vertices[edges[e].to] - soup.vertices[edges[e].from]).norm();
      long n = open.leaving[edges[e].to_id];
      if (n == -2) n = turns.next(e);
      if (n == static_cast<long>(start)) break;
      if (n < 0 || used[n]) {
        c.loop = false;
        break;
      }
      e = n;
    }
    chains.push_back(std::move(c));
  }
  return chains;
}

// Chains and loops this far from a plane lie in it (mm).
constexpr double kFlatMm = 1.0;

// The planes of long flat chains (a point, the normal): where the scan ended, or the surface was
// cropped.
std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> scan_end_planes(
    const TriangleSoup& soup, const std::vector<Chain>& chains, double max_length_mm) {
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> ends;
  for (const Chain& c : chains) {
    if (c.length <= max_length_mm || c.corners.size() < 8) continue;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (int v : c.corners) mean += soup.vertices[v];
    mean /= static_cast<double>(c.corners.size());
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (int v : c.corners)
      cov += (soup.vertices[v] - mean) * (soup.vertices[v] - mean).transpose();
    const Eigen::Vector3d normal =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors().col(0);
    double flatness = 0.0;
    for (int v : c.corners)
      flatness = std::max(flatness, std::abs((soup.vertices[v] - mean).dot(normal)));
    if (flatness <= kFlatMm) ends.emplace_back(mean, normal);
  }
  return ends;
}

HoleClosing close_holes(TriangleSoup& soup, const std::vector<int>& id, const EdgeUses& uses,
                        double max_length_mm, bool through_corners) {
  HoleClosing out;
  const OpenEdges open = open_edges(soup, id, uses);
  if (open.edges.empty()) return out;
  CornerTurns turns(soup, id, open, through_corners);
  const std::vector<Chain> chains = open_chains(soup, open, turns);
  // Small loops in the plane of a scan's end (around bone the cut crosses) are part of that end
  // and left open, so that a scan's end reads the same whatever else the surface lost.
  const auto ends = scan_end_planes(soup, chains, max_length_mm);
  for (const Chain& c : chains) {
    const std::vector<int>& loop = c.corners;
    if (!c.loop || loop.size() < 3 || c.length > max_length_mm) continue;
    // A loop through the same corner twice would be closed by a fan folded there: left.
    std::vector<int> ids(loop.size());
    for (size_t k = 0; k < loop.size(); ++k) ids[k] = id[loop[k]];
    std::sort(ids.begin(), ids.end());
    if (std::adjacent_find(ids.begin(), ids.end()) != ids.end()) continue;
    bool at_end = false;
    for (const auto& [point, normal] : ends) {
      bool in_plane = true;
      for (int v : loop) in_plane &= std::abs((soup.vertices[v] - point).dot(normal)) <= kFlatMm;
      at_end |= in_plane;
    }
    if (at_end) continue;
    // The triangles around run the loop as `loop` lists it; the closing ones run it back.
    if (loop.size() == 3) {
      soup.triangles.emplace_back(loop[0], loop[2], loop[1]);
    } else {
      Eigen::Vector3d centre = Eigen::Vector3d::Zero();
      for (int v : loop) centre += soup.vertices[v];
      soup.vertices.push_back(centre / static_cast<double>(loop.size()));
      const int added = static_cast<int>(soup.vertices.size()) - 1;
      for (size_t k = 0; k < loop.size(); ++k)
        soup.triangles.emplace_back(loop[(k + 1) % loop.size()], loop[k], added);
    }
    ++out.closed;
    out.triangles_added += loop.size() == 3 ? 1 : static_cast<long long>(loop.size());
    out.largest_mm = std::max(out.largest_mm, c.length);
  }
  return out;
}

}  // namespace

SoupRepair repair_soup(TriangleSoup& soup, const SoupRepairParams& params) {
  SoupRepair out;
  const bool close = params.close_holes_mm > 0.0;
  if (!params.drop_repeated && !params.orient && !close) return out;
  const std::vector<int> id = position_ids(soup);
  if (params.drop_repeated) out.repeated_dropped = drop_repeated(soup, id);
  if (!params.orient && !close) return out;
  const EdgeUses uses = edge_uses(soup, id);
  if (params.orient) out.orientation = orient(soup, uses);
  if (close) out.holes = close_holes(soup, id, uses, params.close_holes_mm, params.through_corners);
  return out;
}

long long drop_repeated_triangles(TriangleSoup& soup) {
  SoupRepairParams p;
  p.drop_repeated = true;
  return repair_soup(soup, p).repeated_dropped;
}

SoupOrientation orient_consistently(TriangleSoup& soup) {
  SoupRepairParams p;
  p.orient = true;
  return repair_soup(soup, p).orientation;
}

HoleClosing close_small_holes(TriangleSoup& soup, double max_length_mm, bool through_corners) {
  SoupRepairParams p;
  p.close_holes_mm = max_length_mm;
  p.through_corners = through_corners;
  return repair_soup(soup, p).holes;
}

}  // namespace cranioplan
