#pragma once
#include <string>

#include "cranioplan/algorithms/io/mesh_space.h"
#include "cranioplan/model/mesh.h"

namespace cranioplan {

enum class MeshFormat { BinarySTL, BinaryPLY, ThreeMF };

/// The format a path's extension asks for (.stl, .ply or .3mf, case-insensitive); throws
/// InputError for other extensions.
MeshFormat mesh_format_for_path(const std::string& path);

/// The bytes `write_mesh` writes (deterministic: the same mesh gives the same bytes, so the
/// SHA-256 of an export can be checked by replaying a plan). A 3MF holds the mesh as the part
/// "implant" in millimetres (write_3mf.h). The mesh is in the patient's LPS; with `space` RAS
/// (LoadedSkull::file_space: the skull's file declared RAS) it is written in RAS, x and y
/// negated, and an STL's header and a PLY's comment say "SPACE=RAS" as 3D Slicer reads it.
/// Otherwise the coordinates are written as they are, and nothing is declared.
std::string encode_mesh(const SkullMesh& mesh, MeshFormat format,
                        MeshSpace space = MeshSpace::Undeclared);
/// `mesh` in `space`'s coordinates (a copy: x and y negated for RAS).
SkullMesh mesh_in_space(const SkullMesh& mesh, MeshSpace space);
/// Writes the mesh atomically (temporary file in the same folder, then rename). Throws
/// InputError when the file cannot be written.
void write_mesh(const SkullMesh& mesh, const std::string& path, MeshFormat format,
                MeshSpace space = MeshSpace::Undeclared);
inline void write_mesh(const SkullMesh& mesh, const std::string& path,
                       MeshSpace space = MeshSpace::Undeclared) {
  write_mesh(mesh, path, mesh_format_for_path(path), space);
}

}  // namespace cranioplan
