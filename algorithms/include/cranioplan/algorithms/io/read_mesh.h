#pragma once
// Reading surface meshes: STL (binary or ASCII, told apart by content), PLY, OBJ, OFF, VTK
// (legacy polygonal data, ASCII or binary: 3D Slicer's default for models), VTP.
#include <string>
#include <vector>

#include "cranioplan/algorithms/geometry/mesh_components.h"
#include "cranioplan/algorithms/io/mesh_space.h"
#include "cranioplan/model/mesh.h"

namespace cranioplan {

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
  /// The repairs of a skull's soup (repair_soup), each with a warning (MeshFile::
  /// repeated_dropped, triangles_turned, holes_closed): triangles with the same three corners as
  /// another dropped (a surface written twice doubles every crossing there, and the plan moves:
  /// docs/ARCHITECTURE.md, "Errors, in three tiers"); patches that wind
  /// against their neighbours turned to agree with the larger part of their piece (a halfedge
  /// mesh cannot join two triangles that run a shared edge alike: read as they came, such seams
  /// are split into holes and reported as non-manifold); small holes closed, wound as their
  /// neighbours (triangles a program lost, through which a line's crossings no longer tell the
  /// bone's inside). In that order, before `orient_outward`. None by default: as the file gives
  /// it.
  SoupRepairParams repairs;
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
  long long triangles_turned = 0;     ///< ReadMeshParams::repairs turned them
  long long patches_turned = 0;       ///< in this many patches
  long long repeated_dropped = 0;     ///< ReadMeshParams::repairs dropped them
  long long holes_closed = 0;         ///< ReadMeshParams::repairs closed them
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

/// What the repairs of a skull's soup (ReadMeshParams::repairs) did, one sentence each, without the
/// file's name; none when they found nothing ("12 triangles repeat another's three corners (the
/// surface written twice there); the copies were dropped").
std::vector<std::string> describe_repairs(const SoupRepair& done);

/// Reads a mesh; STL vertices are welded (identical coordinates become one vertex).
/// Throws InputError naming the file and the problem: missing, empty, truncated, garbage,
/// NaN/Inf coordinates, no usable triangle, unknown format.
MeshFile read_mesh(const std::string& path, const ReadMeshParams& params = {});
/// The same, the mesh built in `mesh` and the file's own mesh left empty (OpenMesh meshes
/// cannot be moved: assigning one copies it).
MeshFile read_mesh(const std::string& path, const ReadMeshParams& params, SkullMesh& mesh);

}  // namespace cranioplan
