#include "cranioplan/model/mesh.h"

#include <Eigen/Geometry>
#include <OpenMesh/Core/System/omstream.hh>
#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <memory>
#include <numeric>

namespace cranioplan {

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

// Outgoing halfedges per vertex, as compressed lists, for the faces marked in `keep`.
struct OutgoingLists {
  std::vector<int> start, out;
  OutgoingLists(const std::vector<int>& corner, int nv, const std::vector<char>& keep)
      : start(static_cast<size_t>(nv) + 1, 0) {
    for (size_t he = 0; he < corner.size(); ++he)
      if (keep[he / 3]) ++start[corner[he] + 1];
    for (int v = 0; v < nv; ++v) start[v + 1] += start[v];
    out.resize(start[nv]);
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (size_t he = 0; he < corner.size(); ++he)
      if (keep[he / 3]) out[fill[corner[he]]++] = static_cast<int>(he);
  }
  // The halfedge u → v, or -1.
  int find(const std::vector<int>& corner, int u, int v) const {
    for (int i = start[u]; i < start[u + 1]; ++i)
      if (corner[next_corner(static_cast<size_t>(out[i]))] == v) return out[i];
    return -1;
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

// x rounded to the nearest single-precision value (ties to even, as a float conversion rounds),
// by its mantissa: GCC 12's SLP vectorizer at -O2/-O3 drops the round trip
// static_cast<double>(static_cast<float>(x)) over Eigen vectors (measured on this machine: the
// coordinates came back unrounded).
double round_to_single(double x) {
  int exponent = 0;
  const double mantissa = std::frexp(x, &exponent);
  const double rounded = std::ldexp(std::nearbyint(std::ldexp(mantissa, 24)), exponent - 24);
  return rounded == 0.0 ? 0.0 : rounded;  // −0 is +0: equal positions are one vertex, bit for bit
}

}  // namespace

void make_canonical(TriangleSoup& soup) {
  for (auto& v : soup.vertices)
    for (int k = 0; k < 3; ++k) v[k] = round_to_single(v[k]);
  auto less = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
  };
  std::vector<int> order(soup.vertices.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return less(soup.vertices[a], soup.vertices[b]); });
  std::vector<int> id(soup.vertices.size());
  std::vector<Eigen::Vector3d> vertices;
  vertices.reserve(soup.vertices.size());
  for (int i : order) {
    if (vertices.empty() || vertices.back() != soup.vertices[i])
      vertices.push_back(soup.vertices[i]);
    id[i] = static_cast<int>(vertices.size()) - 1;
  }
  for (auto& t : soup.triangles) {
    Eigen::Vector3i u(id[t[0]], id[t[1]], id[t[2]]);
    const int first = u[0] <= u[1] && u[0] <= u[2] ? 0 : u[1] <= u[2] ? 1 : 2;
    t = Eigen::Vector3i(u[first], u[(first + 1) % 3], u[(first + 2) % 3]);
  }
  std::sort(soup.triangles.begin(), soup.triangles.end(),
            [](const Eigen::Vector3i& a, const Eigen::Vector3i& b) {
              return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
            });
  soup.vertices = std::move(vertices);
}

namespace {

// Each fan of triangles around a vertex beyond the first (faces joined through shared edges)
// gets its own copy of the vertex: `corner` is renumbered to the copies, `nv` and `source` (the
// input vertex of each mesh vertex) grow with them.
void split_complex_vertices(const OutgoingLists& lists, std::vector<int>& corner, int& nv,
                            std::vector<int>& source, BuildMeshStats& stats) {
  const int original_count = nv;
  std::vector<int> parent, copy;
  for (int v = 0; v < original_count; ++v) {
    const int a = lists.start[v], n = lists.start[v + 1] - a;
    if (n < 2) continue;
    parent.resize(n);
    for (int i = 0; i < n; ++i) parent[i] = i;
    auto root = [&](int x) {
      while (parent[x] != x) x = parent[x] = parent[parent[x]];
      return x;
    };
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        // Face i leaves v towards w and face j arrives at v from w: they share edge v–w.
        const size_t hi = static_cast<size_t>(lists.out[a + i]);
        const size_t hj = static_cast<size_t>(lists.out[a + j]);
        if (i != j && corner[next_corner(hi)] == corner[prev_corner(hj)]) parent[root(i)] = root(j);
      }
    copy.assign(n, -1);
    const int keep = root(0);
    for (int i = 0; i < n; ++i) {
      const int r = root(i);
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
// meet (complex vertices, as marching cubes makes) get one copy per extra fan.
SkullMesh build_mesh(const TriangleSoup& soup, BuildMeshStats* stats) {
  SkullMesh mesh;
  build_mesh(soup, mesh, stats);
  return mesh;
}

void build_mesh(const TriangleSoup& soup, SkullMesh& mesh, BuildMeshStats* stats) {
  // Complex faces are counted in the stats and reported by the callers in plain words;
  // OpenMesh's own log lines on stderr would only confuse.
  omerr().disable();
  BuildMeshStats local;
  const int n_in = static_cast<int>(soup.vertices.size());

  // Non-degenerate faces and the vertices they use, renumbered in input order.
  std::vector<int> faces;
  faces.reserve(soup.triangles.size());
  std::vector<int> id(n_in, -1);
  for (size_t i = 0; i < soup.triangles.size(); ++i) {
    const auto& t = soup.triangles[i];
    assert(t.minCoeff() >= 0 && t.maxCoeff() < n_in && "triangle index out of range");
    if (is_degenerate(soup, t)) {
      ++local.degenerate_dropped;
      continue;
    }
    faces.push_back(static_cast<int>(i));
    for (int k = 0; k < 3; ++k) id[t[k]] = 0;
  }
  std::vector<int> source;  // input vertex of each mesh vertex
  source.reserve(n_in);
  for (int i = 0; i < n_in; ++i)
    if (id[i] == 0) {
      id[i] = static_cast<int>(source.size());
      source.push_back(i);
    }
  int nv = static_cast<int>(source.size());
  const size_t nf = faces.size(), nh = nf * 3;
  std::vector<int> corner(nh);
  for (size_t he = 0; he < nh; ++he)
    corner[he] = id[soup.triangles[faces[he / 3]][static_cast<int>(he % 3)]];

  // 1. Accept faces in order unless one of their directed edges is taken by an accepted face.
  std::vector<char> accepted(nf, 0);
  std::vector<int> deferred;
  auto lists = std::make_unique<OutgoingLists>(corner, nv, std::vector<char>(nf, 1));
  for (size_t f = 0; f < nf; ++f) {
    bool ok = true;
    for (size_t he = f * 3; he < f * 3 + 3 && ok; ++he) {
      const int u = corner[he], v = corner[next_corner(he)];
      for (int i = lists->start[u]; i < lists->start[u + 1] && ok; ++i) {
        const size_t other = static_cast<size_t>(lists->out[i]);
        ok = !(other / 3 != f && accepted[other / 3] && corner[next_corner(other)] == v);
      }
    }
    if (ok)
      accepted[f] = 1;
    else
      deferred.push_back(static_cast<int>(f));
  }
  if (!deferred.empty()) lists = std::make_unique<OutgoingLists>(corner, nv, accepted);

  // 2. Give each extra fan of a complex vertex its own copy of the vertex.
  const int original_count = nv;
  split_complex_vertices(*lists, corner, nv, source, local);
  if (nv != original_count) lists = std::make_unique<OutgoingLists>(corner, nv, accepted);

  // 3. Edges: the first halfedge of a pair creates the edge; its twin reuses it.
  std::vector<int> halfedge(nh, -1);  // mesh halfedge index of each accepted face halfedge
  int ne = 0;
  for (size_t he = 0; he < nh; ++he) {
    if (!accepted[he / 3]) continue;
    const int opp = lists->find(corner, corner[next_corner(he)], corner[he]);
    halfedge[he] = opp >= 0 && static_cast<size_t>(opp) < he ? (halfedge[opp] ^ 1) : 2 * ne++;
  }
  int n_accepted = 0;
  for (char a : accepted) n_accepted += a;

  mesh.clear();
  mesh.resize(nv, ne, n_accepted);
  for (int v = 0; v < nv; ++v) mesh.set_point(VH(v), to_point(soup.vertices[source[v]]));
  std::vector<int> boundary_out(nv, -1), boundary_to(nv, -1);
  int fi = 0;
  for (size_t f = 0; f < nf; ++f) {
    if (!accepted[f]) continue;
    const SkullMesh::FaceHandle fh(fi++);
    mesh.set_halfedge_handle(fh, HH(halfedge[f * 3]));
    for (size_t he = f * 3; he < f * 3 + 3; ++he) {
      const HH h(halfedge[he]);
      const int u = corner[he], v = corner[next_corner(he)];
      mesh.set_vertex_handle(h, VH(v));
      mesh.set_vertex_handle(mesh.opposite_halfedge_handle(h), VH(u));
      mesh.set_next_halfedge_handle(h, HH(halfedge[next_corner(he)]));
      mesh.set_face_handle(h, fh);
      mesh.set_halfedge_handle(VH(u), h);
      if (lists->find(corner, v, u) < 0) {  // no face on the other side: a boundary v → u
        boundary_out[v] = halfedge[he] ^ 1;
        boundary_to[v] = u;
      }
    }
  }
  for (int v = 0; v < nv; ++v) {
    if (boundary_out[v] < 0) continue;
    mesh.set_next_halfedge_handle(HH(boundary_out[v]), HH(boundary_out[boundary_to[v]]));
    mesh.set_halfedge_handle(VH(v), HH(boundary_out[v]));  // boundary vertices start on it
  }
  // 4. The faces step 1 set aside.
  for (int f : deferred) {
    std::array<Eigen::Vector3d, 3> p;
    std::array<VH, 3> v;
    for (int k = 0; k < 3; ++k) {
      const int c = corner[static_cast<size_t>(f) * 3 + k];
      p[k] = soup.vertices[source[c]];
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

double signed_volume(const SkullMesh& mesh) {
  double six_v = 0.0;
  for (auto fh : mesh.faces()) {
    std::array<Eigen::Vector3d, 3> p;
    int k = 0;
    for (auto vh : mesh.fv_range(fh)) p[k++] = to_eigen(mesh.point(vh));
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
