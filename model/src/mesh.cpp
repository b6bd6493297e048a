#include "cranioplan/model/mesh.h"

#include <Eigen/Geometry>
#include <OpenMesh/Core/System/omstream.hh>
#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>

#include "cranioplan/model/parallel.h"

namespace cranioplan {

Eigen::Vector3d FaceCorners::cross() const { return (p[1] - p[0]).cross(p[2] - p[0]); }

namespace {

using VH = SkullMesh::VertexHandle;
using HH = SkullMesh::HalfedgeHandle;

bool is_degenerate(const TriangleSoup& soup, const Eigen::Vector3i& t) {
  if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) return true;
  const Eigen::Vector3d& a = soup.vertices[t[0]];
  return (soup.vertices[t[1]] - a).cross(soup.vertices[t[2]] - a).squaredNorm() <= 0.0;
}

// Halfedge he = 3·face + corner runs from corner[he] to corner[next(he)].
inline size_t next_corner(size_t he) { return he - he % 3 + (he + 1) % 3; }
inline size_t prev_corner(size_t he) { return he - he % 3 + (he + 2) % 3; }

// Vertices with more outgoing halfedges than this (a pole, a cap triangulated as a fan) are
// searched by sorting instead of pair by pair, which would take seconds from valences of tens
// of thousands.
constexpr int kLongList = 64;

// Outgoing halfedges per vertex, as compressed lists, for the faces marked in `keep`. Long
// lists also in order of destination (`by_dest`, the same range), for finding a halfedge by
// bisection.
struct OutgoingLists {
  std::vector<int> start, out, by_dest;
  OutgoingLists(const std::vector<int>& corner, int nv, const std::vector<char>& keep)
      : start(static_cast<size_t>(nv) + 1, 0) {
    for (size_t he = 0; he < corner.size(); ++he)
      if (keep[he / 3]) ++start[corner[he] + 1];
    bool any_long = false;
    for (int v = 0; v < nv; ++v) {
      any_long = any_long || start[v + 1] > kLongList;
      start[v + 1] += start[v];
    }
    out.resize(start[nv]);
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (size_t he = 0; he < corner.size(); ++he)
      if (keep[he / 3]) out[fill[corner[he]]++] = static_cast<int>(he);
    if (!any_long) return;
    by_dest.resize(out.size());
    for (int v = 0; v < nv; ++v) {
      if (start[v + 1] - start[v] <= kLongList) continue;
      const auto first = by_dest.begin() + start[v], last = by_dest.begin() + start[v + 1];
      std::copy(out.begin() + start[v], out.begin() + start[v + 1], first);
      std::sort(first, last, [&](int a, int b) {  // by destination, then in list order
        const int da = corner[next_corner(static_cast<size_t>(a))];
        const int db = corner[next_corner(static_cast<size_t>(b))];
        return da != db ? da < db : a < b;
      });
    }
  }
  bool is_long(int u) const { return start[u + 1] - start[u] > kLongList; }
  // Calls f(he) for every halfedge u → v.
  template <class F>
  void each_to(const std::vector<int>& corner, int u, int v, F&& f) const {
    auto dest = [&](int he) { return corner[next_corner(static_cast<size_t>(he))]; };
    if (!is_long(u)) {
      for (int i = start[u]; i < start[u + 1]; ++i)
        if (dest(out[i]) == v) f(static_cast<size_t>(out[i]));
      return;
    }
    const auto last = by_dest.begin() + start[u + 1];
    auto it = std::lower_bound(by_dest.begin() + start[u], last, v,
                               [&](int he, int d) { return dest(he) < d; });
    for (; it != last && dest(*it) == v; ++it) f(static_cast<size_t>(*it));
  }
  // The halfedge u → v (the first in list order), or -1.
  int find(const std::vector<int>& corner, int u, int v) const {
    int first = -1;
    each_to(corner, u, v, [&](size_t he) {
      if (first < 0) first = static_cast<int>(he);
    });
    return first;
  }
};

// Adds a triangle; where it would make a complex edge or vertex, adds it on its own copies of
// the vertices (as OpenMesh's readers do) so no triangle is lost.
void add_face_or_split(SkullMesh& mesh, const std::array<Eigen::Vector3d, 3>& p,
                       const std::array<VH, 3>& v, BuildMeshStats& stats) {
  std::vector<VH> face(v.begin(), v.end());
  if (mesh.add_face(face).is_valid()) return;
  for (int k = 0; k < 3; ++k) face[k] = mesh.add_vertex(to_point(p[k]));
  mesh.add_face(face);
  ++stats.nonmanifold_split;
}

// x rounded to 24 significant bits, ties to even (as a conversion to float rounds, without its
// range limits), by clearing the low 29 of the 52 stored mantissa bits: a carry into the
// exponent is the next power of two, as it should be. Zeros, subnormals, infinities and NaNs
// (none reach here from a file: the readers refuse non-finite coordinates) go through frexp.
// Not static_cast<double>(static_cast<float>(x)): GCC 12's SLP vectorizer at -O2/-O3 drops
// that round trip over Eigen vectors: the coordinates come back unrounded.
double round_to_single(double x) {
  uint64_t bits = 0;
  std::memcpy(&bits, &x, sizeof bits);
  const uint64_t exponent = (bits >> 52) & 0x7ff;
  if (exponent == 0 || exponent == 0x7ff) {
    int e = 0;
    const double mantissa = std::frexp(x, &e);
    const double rounded = std::ldexp(std::nearbyint(std::ldexp(mantissa, 24)), e - 24);
    return rounded == 0.0 ? 0.0 : rounded;  // −0 is +0: equal positions are one vertex
  }
  constexpr uint64_t kDropped = (uint64_t{1} << 29) - 1, kHalf = uint64_t{1} << 28;
  const uint64_t low = bits & kDropped;
  bits &= ~kDropped;
  if (low > kHalf || (low == kHalf && (bits & (kDropped + 1)) != 0)) bits += kDropped + 1;
  std::memcpy(&x, &bits, sizeof x);
  return x;
}

}  // namespace

void make_canonical(TriangleSoup& soup) {
  // Vertices sorted as values (position and input index side by side) rather than through an
  // index array: the comparisons read contiguous memory.
  struct Keyed {
    double x, y, z;
    int index;
  };
  std::vector<Keyed> keyed(soup.vertices.size());
  for (size_t i = 0; i < keyed.size(); ++i) {
    const Eigen::Vector3d& v = soup.vertices[i];
    keyed[i] = {round_to_single(v.x()), round_to_single(v.y()), round_to_single(v.z()),
                static_cast<int>(i)};
  }
  auto less = [](const Keyed& a, const Keyed& b) {
    return a.x != b.x ? a.x < b.x : a.y != b.y ? a.y < b.y : a.z < b.z;
  };
  // Equal positions may come out in either order; they become one vertex, so the result does
  // not depend on it (nor on the thread count).
  parallel_sort(keyed.begin(), keyed.end(), less);
  std::vector<int> id(soup.vertices.size());
  std::vector<Eigen::Vector3d> vertices;
  vertices.reserve(soup.vertices.size());
  for (const Keyed& k : keyed) {
    const Eigen::Vector3d p(k.x, k.y, k.z);
    if (vertices.empty() || vertices.back() != p) vertices.push_back(p);
    id[k.index] = static_cast<int>(vertices.size()) - 1;
  }
  // Triangles from their smallest corner, in lexicographic order: counted out by that corner
  // (a bucket per vertex, a few triangles each), then each bucket sorted by the other two.
  const size_t nv = vertices.size();
  std::vector<int> start(nv + 1, 0);
  for (auto& t : soup.triangles) {
    const Eigen::Vector3i u(id[t[0]], id[t[1]], id[t[2]]);
    const int first = u[0] <= u[1] && u[0] <= u[2] ? 0 : u[1] <= u[2] ? 1 : 2;
    t = Eigen::Vector3i(u[first], u[(first + 1) % 3], u[(first + 2) % 3]);
    ++start[t[0] + 1];
  }
  for (size_t v = 0; v < nv; ++v) start[v + 1] += start[v];
  std::vector<Eigen::Vector3i> sorted(soup.triangles.size());
  {
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (const auto& t : soup.triangles) sorted[fill[t[0]]++] = t;
  }
  auto later = [](const Eigen::Vector3i& a, const Eigen::Vector3i& b) {
    return a[1] != b[1] ? a[1] < b[1] : a[2] < b[2];
  };
  for (size_t v = 0; v < nv; ++v)
    if (start[v + 1] - start[v] > 1)
      std::sort(sorted.begin() + start[v], sorted.begin() + start[v + 1], later);
  soup.triangles = std::move(sorted);
  soup.vertices = std::move(vertices);
}

namespace {

// Whether the triangles around v fall into more than one fan (faces joined through shared
// edges). Leaves each outgoing halfedge's fan (a root in `parent`) for the caller; `ends` is
// scratch for the two other corners of each face.
bool fans_around(const OutgoingLists& lists, const std::vector<int>& corner, int v,
                 std::vector<int>& parent, std::vector<std::array<int, 2>>& ends) {
  const int a = lists.start[v], n = lists.start[v + 1] - a;
  if (n < 2) return false;
  parent.resize(n);
  ends.resize(n);
  for (int i = 0; i < n; ++i) {
    const size_t h = static_cast<size_t>(lists.out[a + i]);
    parent[i] = i;
    ends[i] = {corner[next_corner(h)], corner[prev_corner(h)]};  // face i: v → w, x → v
  }
  auto root = [&](int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  // Face i leaves v towards w and face j arrives at v from w: they share edge v–w. (The fans
  // are the same whatever order the faces are joined in.)
  if (n <= kLongList) {
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        if (i != j && ends[i][0] == ends[j][1]) parent[root(i)] = root(j);
  } else {
    std::vector<int> by_from(n);  // faces in order of the corner they arrive from
    for (int j = 0; j < n; ++j) by_from[j] = j;
    std::sort(by_from.begin(), by_from.end(),
              [&](int a, int b) { return ends[a][1] < ends[b][1]; });
    for (int i = 0; i < n; ++i) {
      auto it = std::lower_bound(by_from.begin(), by_from.end(), ends[i][0],
                                 [&](int j, int w) { return ends[j][1] < w; });
      for (; it != by_from.end() && ends[*it][1] == ends[i][0]; ++it)
        if (*it != i) parent[root(i)] = root(*it);
    }
  }
  bool several = false;
  for (int i = 0; i < n; ++i) {
    parent[i] = root(i);
    several = several || parent[i] != parent[0];
  }
  return several;
}

// Each fan of triangles around a vertex beyond the first gets its own copy of the vertex:
// `corner` is renumbered to the copies, `nv` and `source` (the input vertex of each mesh vertex)
// grow with them. Which vertices have several fans is found on all threads (a split never
// changes another vertex's fans: two faces sharing an edge u–v share it at both ends); the
// copies are made in vertex order.
void split_complex_vertices(const OutgoingLists& lists, std::vector<int>& corner, int& nv,
                            std::vector<int>& source, BuildMeshStats& stats) {
  const int original_count = nv;
  std::vector<char> complex(static_cast<size_t>(original_count), 0);
  parallel_for(static_cast<size_t>(original_count), [&](size_t begin, size_t end) {
    std::vector<int> parent;
    std::vector<std::array<int, 2>> ends;
    for (size_t v = begin; v < end; ++v)
      complex[v] = fans_around(lists, corner, static_cast<int>(v), parent, ends) ? 1 : 0;
  });
  std::vector<int> parent, copy;
  std::vector<std::array<int, 2>> ends;
  for (int v = 0; v < original_count; ++v) {
    if (!complex[v]) continue;
    fans_around(lists, corner, v, parent, ends);
    const int a = lists.start[v], n = lists.start[v + 1] - a;
    copy.assign(n, -1);
    const int keep = parent[0];
    for (int i = 0; i < n; ++i) {
      const int r = parent[i];
      if (r == keep) continue;
      if (copy[r] < 0) {
        copy[r] = nv++;
        source.push_back(source[v]);
        ++stats.nonmanifold_split;
      }
      corner[static_cast<size_t>(lists.out[a + i])] = copy[r];
    }
  }
}

}  // namespace

// Builds the halfedge structure in bulk: sizes every OpenMesh array once (resize) and links
// halfedges from per-vertex outgoing lists, instead of add_vertex/add_face with their per-element
// checks. Faces that would reuse a directed edge (non-manifold edges, flipped neighbours) are
// added afterwards with add_face, split if need be; vertices where several fans of triangles
// meet (complex vertices, as marching cubes makes) get one copy per extra fan. The searches
// run on all threads; whatever depends on order (which of two faces claiming one directed
// edge comes first, the numbering of copies and edges) is decided in input order, so the mesh
// does not depend on the thread count.
SkullMesh build_mesh(const TriangleSoup& soup, BuildMeshStats* stats) {
  SkullMesh mesh;
  build_mesh(soup, mesh, stats);
  return mesh;
}

namespace {

// The soup's non-degenerate faces (`faces`, by soup index) and the vertices they use, renumbered
// in input order (`source`: the soup vertex of each), and each face's three corners in that
// numbering.
struct UsedCorners {
  std::vector<int> faces, source, corner;
};

UsedCorners used_corners(const TriangleSoup& soup, BuildMeshStats& stats) {
  const int n_in = static_cast<int>(soup.vertices.size());
  std::vector<char> degenerate(soup.triangles.size());
  parallel_for(soup.triangles.size(), [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      const auto& t = soup.triangles[i];
      assert(t.minCoeff() >= 0 && t.maxCoeff() < n_in && "triangle index out of range");
      degenerate[i] = is_degenerate(soup, t) ? 1 : 0;
    }
  });
  UsedCorners out;
  out.faces.reserve(soup.triangles.size());
  std::vector<int> id(n_in, -1);
  for (size_t i = 0; i < soup.triangles.size(); ++i) {
    if (degenerate[i]) {
      ++stats.degenerate_dropped;
      continue;
    }
    out.faces.push_back(static_cast<int>(i));
    for (int k = 0; k < 3; ++k) id[soup.triangles[i][k]] = 0;
  }
  out.source.reserve(n_in);
  for (int i = 0; i < n_in; ++i)
    if (id[i] == 0) {
      id[i] = static_cast<int>(out.source.size());
      out.source.push_back(i);
    }
  const size_t nf = out.faces.size();
  out.corner.resize(nf * 3);
  parallel_for(nf, [&](size_t begin, size_t end) {
    for (size_t f = begin; f < end; ++f)
      for (int k = 0; k < 3; ++k) out.corner[f * 3 + k] = id[soup.triangles[out.faces[f]][k]];
  });
  return out;
}

// Accepts faces in order unless one of their directed edges is taken by an accepted face. A
// face none of whose directed edges another face repeats is accepted in any order; only the
// faces with a repeated directed edge (found on all threads) are decided in order. Returns the
// faces set aside (`accepted` 0), in order.
std::vector<int> accept_faces(const std::vector<int>& corner, int nv, const OutgoingLists& lists,
                              std::vector<char>& accepted) {
  const size_t nf = accepted.size(), nh = nf * 3;
  std::vector<char> repeated(nh, 0);  // per halfedge: another face has the same directed edge
  parallel_for(static_cast<size_t>(nv), [&](size_t begin, size_t end) {
    for (size_t u = begin; u < end; ++u) {
      const int a = lists.start[u], b = lists.start[u + 1];
      auto dest = [&](int he) { return corner[next_corner(static_cast<size_t>(he))]; };
      if (lists.is_long(static_cast<int>(u))) {  // runs of one destination, in `by_dest`
        for (int i = a; i + 1 < b; ++i)
          if (dest(lists.by_dest[i]) == dest(lists.by_dest[i + 1]))
            repeated[lists.by_dest[i]] = repeated[lists.by_dest[i + 1]] = 1;
        continue;
      }
      for (int i = a; i < b; ++i)
        for (int j = i + 1; j < b; ++j)
          if (dest(lists.out[i]) == dest(lists.out[j]))
            repeated[lists.out[i]] = repeated[lists.out[j]] = 1;
    }
  });
  std::vector<int> deferred;
  std::vector<size_t> contested;
  for (size_t f = 0; f < nf; ++f)
    if (repeated[f * 3] || repeated[f * 3 + 1] || repeated[f * 3 + 2]) {
      contested.push_back(f);
      accepted[f] = 0;
    }
  for (size_t f : contested) {
    bool ok = true;
    for (size_t he = f * 3; he < f * 3 + 3 && ok; ++he) {
      const int u = corner[he], v = corner[next_corner(he)];
      lists.each_to(corner, u, v,
                    [&](size_t other) { ok = ok && !(other / 3 != f && accepted[other / 3]); });
    }
    if (ok)
      accepted[f] = 1;
    else
      deferred.push_back(static_cast<int>(f));
  }
  return deferred;
}

// The accepted faces as the mesh's connectivity: twins, then edges (the first halfedge of a
// pair creates the edge; its twin reuses it), each face's halfedges (and the twin of one on the
// border, which has no face to set it), each vertex's point and its last outgoing halfedge in
// input order, or the border halfedge that leaves it. Room is kept for `extra` vertices and
// edges and `extra_faces` faces.
void link_accepted(const TriangleSoup& soup, const std::vector<int>& corner,
                   const std::vector<int>& source, int nv, const OutgoingLists& lists,
                   const std::vector<char>& accepted, size_t extra, size_t extra_faces,
                   SkullMesh& mesh) {
  const size_t nf = accepted.size(), nh = nf * 3;
  std::vector<int> twin(nh, -1);
  parallel_for(nh, [&](size_t begin, size_t end) {
    for (size_t he = begin; he < end; ++he)
      if (accepted[he / 3]) twin[he] = lists.find(corner, corner[next_corner(he)], corner[he]);
  });
  std::vector<int> halfedge(nh, -1);  // mesh halfedge index of each accepted face halfedge
  std::vector<int> face_index(nf, -1);
  int ne = 0, n_accepted = 0;
  for (size_t he = 0; he < nh; ++he) {
    if (!accepted[he / 3]) continue;
    const int opp = twin[he];
    halfedge[he] = opp >= 0 && static_cast<size_t>(opp) < he ? (halfedge[opp] ^ 1) : 2 * ne++;
    if (he % 3 == 0) face_index[he / 3] = n_accepted++;
  }
  mesh.clear();
  mesh.reserve(nv + extra, ne + extra, n_accepted + extra_faces);
  mesh.resize(nv, ne, n_accepted);
  parallel_for(nf, [&](size_t begin, size_t end) {
    for (size_t f = begin; f < end; ++f) {
      if (!accepted[f]) continue;
      const SkullMesh::FaceHandle fh(face_index[f]);
      mesh.set_halfedge_handle(fh, HH(halfedge[f * 3]));
      for (size_t he = f * 3; he < f * 3 + 3; ++he) {
        const HH h(halfedge[he]);
        mesh.set_vertex_handle(h, VH(corner[next_corner(he)]));
        if (twin[he] < 0) mesh.set_vertex_handle(mesh.opposite_halfedge_handle(h), VH(corner[he]));
        mesh.set_next_halfedge_handle(h, HH(halfedge[next_corner(he)]));
        mesh.set_face_handle(h, fh);
      }
    }
  });
  std::vector<int> boundary_out(nv, -1), boundary_to(nv, -1);
  parallel_for(static_cast<size_t>(nv), [&](size_t begin, size_t end) {
    for (size_t v = begin; v < end; ++v) {
      mesh.set_point(VH(static_cast<int>(v)), to_point(soup.vertices[source[v]]));
      const int a = lists.start[v], b = lists.start[v + 1];
      if (a == b) continue;
      mesh.set_halfedge_handle(VH(static_cast<int>(v)), HH(halfedge[lists.out[b - 1]]));
      for (int i = a; i < b; ++i) {
        // The face's halfedge arriving at v; with no twin, the border leaves v along it.
        const size_t in = prev_corner(static_cast<size_t>(lists.out[i]));
        if (twin[in] >= 0) continue;
        boundary_out[v] = halfedge[in] ^ 1;
        boundary_to[v] = corner[in];
      }
    }
  });
  for (int v = 0; v < nv; ++v) {
    if (boundary_out[v] < 0) continue;
    mesh.set_next_halfedge_handle(HH(boundary_out[v]), HH(boundary_out[boundary_to[v]]));
    mesh.set_halfedge_handle(VH(v), HH(boundary_out[v]));  // boundary vertices start on it
  }
}

}  // namespace

void build_mesh(const TriangleSoup& soup, SkullMesh& mesh, BuildMeshStats* stats) {
  // Complex faces are counted in the stats and reported by the callers in plain words;
  // OpenMesh's own log lines on stderr would only confuse.
  omerr().disable();
  BuildMeshStats local;
  UsedCorners used = used_corners(soup, local);
  std::vector<int>& corner = used.corner;
  int nv = static_cast<int>(used.source.size());
  const size_t nf = used.faces.size();

  // 1. Faces accepted in order; those whose directed edges an accepted face took, set aside.
  std::vector<char> accepted(nf, 1);
  auto lists = std::make_unique<OutgoingLists>(corner, nv, accepted);
  const std::vector<int> deferred = accept_faces(corner, nv, *lists, accepted);
  if (!deferred.empty()) lists = std::make_unique<OutgoingLists>(corner, nv, accepted);

  // 2. Give each extra fan of a complex vertex its own copy of the vertex.
  const int original_count = nv;
  split_complex_vertices(*lists, corner, nv, used.source, local);
  if (nv != original_count) lists = std::make_unique<OutgoingLists>(corner, nv, accepted);

  // 3. The mesh's connectivity. Room for the deferred faces too (each may bring three
  // vertices and three edges of its own): OpenMesh grows its arrays and every property one
  // element at a time otherwise, and the first deferred face would copy the whole mesh.
  link_accepted(soup, corner, used.source, nv, *lists, accepted, 3 * deferred.size(),
                deferred.size(), mesh);

  // 4. The faces step 1 set aside.
  for (int f : deferred) {
    std::array<Eigen::Vector3d, 3> p;
    std::array<VH, 3> v;
    for (int k = 0; k < 3; ++k) {
      const int c = corner[static_cast<size_t>(f) * 3 + k];
      p[k] = soup.vertices[used.source[c]];
      v[k] = VH(c);
    }
    add_face_or_split(mesh, p, v, local);
  }
  if (stats) *stats = local;
}

TriangleSoup to_soup(const SkullMesh& mesh) {
  TriangleSoup soup;
  soup.vertices.reserve(mesh.n_vertices());
  for (auto vh : mesh.vertices()) soup.vertices.push_back(to_eigen(mesh.point(vh)));
  soup.triangles.reserve(mesh.n_faces());
  for (auto fh : mesh.faces()) {
    Eigen::Vector3i t;
    int k = 0;
    for (auto vh : mesh.fv_range(fh)) t[k++] = vh.idx();
    soup.triangles.push_back(t);
  }
  return soup;
}

Eigen::Matrix3Xd vertex_matrix(const SkullMesh& mesh) {
  Eigen::Matrix3Xd m(3, mesh.n_vertices());
  for (auto vh : mesh.vertices()) m.col(vh.idx()) = to_eigen(mesh.point(vh));
  return m;
}

Eigen::Vector3d vertex_centroid(const SkullMesh& mesh) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (auto vh : mesh.vertices()) c += to_eigen(mesh.point(vh));
  return c / static_cast<double>(std::max<size_t>(1, mesh.n_vertices()));
}

namespace {
// A face's three corners.
std::array<Eigen::Vector3d, 3> corners(const SkullMesh& mesh, SkullMesh::FaceHandle fh) {
  std::array<Eigen::Vector3d, 3> p;
  int k = 0;
  for (auto vh : mesh.fv_range(fh)) p[k++] = to_eigen(mesh.point(vh));
  return p;
}
}  // namespace

Eigen::Vector3d surface_centroid(const SkullMesh& mesh) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double area = 0.0;
  for (auto fh : mesh.faces()) {
    const std::array<Eigen::Vector3d, 3> p = corners(mesh, fh);
    const double a = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).norm();
    sum += a * (p[0] + p[1] + p[2]) / 3.0;
    area += a;
  }
  return area > 0.0 ? Eigen::Vector3d(sum / area) : vertex_centroid(mesh);
}

double signed_volume(const SkullMesh& mesh) {
  double six_v = 0.0;
  for (auto fh : mesh.faces()) {
    const std::array<Eigen::Vector3d, 3> p = corners(mesh, fh);
    six_v += p[0].dot(p[1].cross(p[2]));
  }
  return six_v / 6.0;
}

double signed_volume(const TriangleSoup& soup, const Eigen::Vector3d& about) {
  double six_v = 0.0;
  for (const auto& t : soup.triangles)
    six_v += (soup.vertices[t[0]] - about)
                 .dot((soup.vertices[t[1]] - about).cross(soup.vertices[t[2]] - about));
  return six_v / 6.0;
}

void flip_orientation(SkullMesh& mesh) {
  TriangleSoup soup = to_soup(mesh);
  for (auto& t : soup.triangles) std::swap(t[1], t[2]);
  mesh = build_mesh(soup);  // a fresh mesh: no property of the old one stays behind
}

}  // namespace cranioplan
