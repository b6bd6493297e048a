#include "cranioplan/model/mesh.h"

#include <Eigen/Geometry>
#include <OpenMesh/Core/System/omstream.hh>
#include <array>

namespace cranioplan {

SkullMesh build_mesh(const TriangleSoup& soup, BuildMeshStats* stats) {
  // Complex faces are counted in the stats and reported by the callers in plain words;
  // OpenMesh's own log lines on stderr would only confuse.
  omerr().disable();
  BuildMeshStats local;
  SkullMesh mesh;
  const int nv = static_cast<int>(soup.vertices.size());
  std::vector<SkullMesh::VertexHandle> handle(nv);
  std::vector<char> used(nv, 0);
  for (const auto& t : soup.triangles)
    for (int k = 0; k < 3; ++k)
      if (t[k] >= 0 && t[k] < nv) used[t[k]] = 1;
  mesh.reserve(nv, soup.triangles.size() * 3 / 2, soup.triangles.size());
  for (int i = 0; i < nv; ++i)
    if (used[i]) handle[i] = mesh.add_vertex(to_point(soup.vertices[i]));

  std::vector<SkullMesh::VertexHandle> face(3);
  for (const auto& t : soup.triangles) {
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) {
      ++local.degenerate_dropped;
      continue;
    }
    const Eigen::Vector3d& a = soup.vertices[t[0]];
    const Eigen::Vector3d& b = soup.vertices[t[1]];
    const Eigen::Vector3d& c = soup.vertices[t[2]];
    if ((b - a).cross(c - a).squaredNorm() <= 0.0) {
      ++local.degenerate_dropped;
      continue;
    }
    for (int k = 0; k < 3; ++k) face[k] = handle[t[k]];
    if (mesh.add_face(face).is_valid()) continue;
    // Complex edge or vertex: add the triangle on its own copies of the vertices.
    for (int k = 0; k < 3; ++k) face[k] = mesh.add_vertex(to_point(soup.vertices[t[k]]));
    mesh.add_face(face);
    ++local.nonmanifold_split;
  }
  // Vertices that only belonged to dropped triangles are isolated: remove them.
  bool any_isolated = false;
  for (auto vh : mesh.vertices()) {
    if (mesh.is_isolated(vh)) {
      mesh.delete_vertex(vh, false);
      any_isolated = true;
    }
  }
  if (any_isolated) mesh.garbage_collection();
  if (stats) *stats = local;
  return mesh;
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

double signed_volume(const TriangleSoup& soup) {
  double six_v = 0.0;
  for (const auto& t : soup.triangles)
    six_v += soup.vertices[t[0]].dot(soup.vertices[t[1]].cross(soup.vertices[t[2]]));
  return six_v / 6.0;
}

void flip_orientation(SkullMesh& mesh) {
  TriangleSoup soup = to_soup(mesh);
  for (auto& t : soup.triangles) std::swap(t[1], t[2]);
  mesh = build_mesh(soup);
}

}  // namespace cranioplan
