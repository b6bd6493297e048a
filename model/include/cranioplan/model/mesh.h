#pragma once
// Triangle meshes of skulls and implants: OpenMesh with double-precision points, lengths in mm.
#include <Eigen/Core>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <array>
#include <vector>

namespace cranioplan {

struct MeshTraits : public OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3d;
  using Normal = OpenMesh::Vec3d;
  VertexAttributes(OpenMesh::Attributes::Normal | OpenMesh::Attributes::Status);
  FaceAttributes(OpenMesh::Attributes::Normal | OpenMesh::Attributes::Status);
  EdgeAttributes(OpenMesh::Attributes::Status);
  HalfedgeAttributes(OpenMesh::Attributes::PrevHalfedge | OpenMesh::Attributes::Status);
};

/// A skull, mirrored skull or implant surface. Points in mm, faces counter-clockwise seen from
/// outside (outward normals).
using SkullMesh = OpenMesh::TriMesh_ArrayKernelT<MeshTraits>;

inline Eigen::Vector3d to_eigen(const OpenMesh::Vec3d& p) { return {p[0], p[1], p[2]}; }
inline OpenMesh::Vec3d to_point(const Eigen::Vector3d& p) { return {p.x(), p.y(), p.z()}; }

/// A triangle's corners in the face's order (counter-clockwise seen from outside): their
/// vertex indices and positions.
struct FaceCorners {
  std::array<int, 3> ids;
  std::array<Eigen::Vector3d, 3> p;
  /// (p1 − p0) × (p2 − p0): along the face's normal, its length twice the area.
  Eigen::Vector3d cross() const;
};
inline FaceCorners face_corners(const SkullMesh& mesh, SkullMesh::FaceHandle fh) {
  FaceCorners c;
  int k = 0;
  for (auto vh : mesh.fv_range(fh)) {
    c.ids[k] = vh.idx();
    c.p[k++] = to_eigen(mesh.point(vh));
  }
  return c;
}

/// Indexed triangle soup: the plain form meshes take on their way in and out of files.
struct TriangleSoup {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Eigen::Vector3i> triangles;
};

/// Result of building a SkullMesh from an indexed soup.
struct BuildMeshStats {
  long long degenerate_dropped = 0;  ///< triangles with repeated vertices or zero area
  long long nonmanifold_split = 0;   ///< faces added with duplicated vertices (complex edges)
};

/// Puts the soup in a form that depends only on its triangles: coordinates rounded to single
/// precision (as STL files hold them), identical positions made one vertex, vertices in
/// lexicographic order of position, each triangle starting at its smallest vertex (its
/// orientation kept) and the triangles in lexicographic order. The same surface read from a CT,
/// from an STL of it or from a PLY in another vertex order then gives the same soup, and so the
/// same plan: sampling by vertex index does not depend on how the file listed them.
void make_canonical(TriangleSoup& soup);

/// Builds a mesh from an indexed soup. Triangles with a repeated index or zero area are dropped;
/// faces that would make a complex edge are added on duplicated vertices (as OpenMesh's readers
/// do), so that no triangle of the input is lost. Unused vertices are not added.
SkullMesh build_mesh(const TriangleSoup& soup, BuildMeshStats* stats = nullptr);
/// The same, built in `into` (whatever it held is cleared). OpenMesh meshes cannot be moved:
/// assigning build_mesh's result to a mesh that already exists copies it, in time and memory
/// (docs/decisions/0030-memory-huge-pages-one-arena-no-copies.md).
void build_mesh(const TriangleSoup& soup, SkullMesh& into, BuildMeshStats* stats = nullptr);

/// The mesh as an indexed soup (vertex order = vertex handle order, garbage collected).
TriangleSoup to_soup(const SkullMesh& mesh);

/// Vertex positions as a 3×N matrix.
Eigen::Matrix3Xd vertex_matrix(const SkullMesh& mesh);

/// Signed volume (mm³) enclosed by the faces: positive for a closed, outward-oriented mesh.
/// Taken about `about` (the same for any point when the surface is closed; for a surface with
/// holes, a point inside it keeps the open parts' share small).
double signed_volume(const SkullMesh& mesh);
/// The mean of the mesh's vertices, mm (zero for a mesh without vertices). It moves towards
/// wherever the triangles are dense: a decimation moves it by millimetres, even into the bone
/// of the skull's base (docs/decisions/0017-the-rays-start-not-the-vertex-centroid.md).
Eigen::Vector3d vertex_centroid(const SkullMesh& mesh);
/// The centroid of the surface, each triangle weighted by its area, mm: the same for the same
/// surface however it is triangulated (the vertex centroid when no face has an area).
Eigen::Vector3d surface_centroid(const SkullMesh& mesh);
double signed_volume(const TriangleSoup& soup,
                     const Eigen::Vector3d& about = Eigen::Vector3d::Zero());

/// Reverses the orientation of every face (normals point the other way).
void flip_orientation(SkullMesh& mesh);

}  // namespace cranioplan
