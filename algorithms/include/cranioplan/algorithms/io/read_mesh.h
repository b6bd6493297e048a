#pragma once
// Reading surface meshes: STL (binary or ASCII, told apart by content), PLY, OBJ, OFF, VTK
// (legacy polygonal data, ASCII or binary: 3D Slicer's default for models), VTP.
#include <string>
#include <vector>

#include "cranioplan/algorithms/io/mesh_space.h"
#include "cranioplan/model/mesh.h"

namespace cranioplan {

struct SoupRepair;

struct ReadMeshParams {
  /// When true, any zero-area or repeated-vertex triangle makes the file an error instead of
  /// being dropped with a warning.
  bool strict = false;
  /// The mesh in canonical form (make_canonical): vertices and triangles in an order that
  /// depends only on the triangles. false: in the file's order.
  bool canonical = true;
  /// A file that declares its coordinates RAS (mesh_space.h: "SPACE=RAS", as 3D Slicer
  /// writes it) is read into the patient's LPS, x and y negated (MeshFile::turned_to_lps).
  /// false: as the file gives them.
  bool space_from_header = false;
  /// The file's length unit in millimetres: coordinates are multiplied by it (before the
  /// canonical form's rounding). 1: the file is in mm.
  double unit_mm = 1.0;
  /// A surface whose triangles wind inward (it encloses a negative volume, taken about its
  /// vertices' centroid) is turned outward, with a warning (MeshFile::turned_outward): some
  /// exporters wind the other way, and a skull's inside and outside tables are told apart by
  /// its normals. false: as the file gives it.
  bool orient_outward = false;
  /// Patches of triangles that wind against their neighbours (some exporters and repairs
  /// leave them) are turned to agree with the larger part of their piece, with a warning
  /// (MeshFile::triangles_turned; orient_consistently). Where two triangles run a shared edge
  /// the same way, a halfedge mesh cannot join them: read as they came, such seams are split
  /// into holes and reported as non-manifold. Done before `orient_outward`. false: as the file
  /// gives it.
  bool orient_consistently = false;
  /// Triangles with the same three corners as another (by position, either winding) are
  /// dropped, with a warning (MeshFile::repeated_dropped; drop_repeated_triangles): a surface
  /// written twice over a patch doubled every crossing there, and the sample with its rim's
  /// patch written twice planned at Dice 0.86 against its own plan. Done before
  /// `orient_consistently`. false: as the file gives it.
  bool drop_repeated_triangles = false;
  /// Holes whose loop of open edges is at most this long (mm) are closed, with a warning
  /// (MeshFile::holes_closed; close_small_holes): triangles a program lost, through which a
  /// line's crossings no longer tell the bone's inside. Done after `orient_consistently`, so
  /// that the closing triangles wind as their neighbours. 0: left open.
  double close_holes_mm = 0.0;
  /// With close_holes_mm, two holes that touch at a corner are told apart and closed each
  /// (SoupRepairParams::through_corners); false: both left open.
  bool close_holes_through_corners = true;
  /// Pieces whose bounding box lies more than this far from the largest piece's (mm) are
  /// dropped, with a warning (MeshFile::pieces_dropped): the CT table, a clip, noise far from
  /// the head. 0: every piece kept.
  double far_piece_mm = 0.0;
};

struct MeshFile {
  SkullMesh mesh;
  std::string format;  ///< "binary STL", "ASCII STL", "PLY", "OBJ", "OFF", "VTK", "VTP"
  MeshSpace space = MeshSpace::Undeclared;  ///< the coordinate system the file declares
  bool turned_to_lps = false;  ///< declared RAS, read in LPS (ReadMeshParams::space_from_header)
  long long triangles_in_file = 0;    ///< triangles (after fan triangulation of polygons)
  long long degenerate_dropped = 0;   ///< zero-area triangles removed
  long long nonmanifold_split = 0;    ///< triangles added on duplicated vertices
  bool turned_outward = false;        ///< ReadMeshParams::orient_outward turned it
  long long triangles_turned = 0;     ///< ReadMeshParams::orient_consistently turned them
  long long patches_turned = 0;       ///< in this many patches
  long long repeated_dropped = 0;     ///< ReadMeshParams::drop_repeated_triangles dropped them
  long long holes_closed = 0;         ///< ReadMeshParams::close_holes_mm closed them
  long long pieces_dropped = 0;       ///< pieces far from the largest (far_piece_mm)
  long long triangles_dropped = 0;    ///< their triangles
  std::vector<std::string> warnings;  ///< one sentence each, naming the file
};

/// The file as an indexed triangle soup (polygons fan-triangulated, STL vertices welded,
/// coordinates checked to be finite), before the halfedge mesh is built: the same product as
/// VTK's readers give, in the file's own coordinates. `format` receives the format's name,
/// `space` the coordinate system the file declares. Throws InputError like read_mesh.
TriangleSoup read_mesh_soup(const std::string& path, std::string* format = nullptr,
                            MeshSpace* space = nullptr);

/// What the repairs of a skull's soup (ReadMeshParams: drop_repeated_triangles,
/// orient_consistently, close_holes_mm) did, one sentence each, without the file's name; none
/// when they found nothing ("12 triangles repeat another's three corners (the surface written
/// twice there); the copies were dropped").
std::vector<std::string> describe_repairs(const SoupRepair& done);

/// Reads a mesh; STL vertices are welded (identical coordinates become one vertex).
/// Throws InputError naming the file and the problem: missing, empty, truncated, garbage,
/// NaN/Inf coordinates, no usable triangle, unknown format.
MeshFile read_mesh(const std::string& path, const ReadMeshParams& params = {});
/// The same, the mesh built in `mesh` and the file's own mesh left empty (OpenMesh meshes
/// cannot be moved: assigning one copies it).
MeshFile read_mesh(const std::string& path, const ReadMeshParams& params, SkullMesh& mesh);

}  // namespace cranioplan
