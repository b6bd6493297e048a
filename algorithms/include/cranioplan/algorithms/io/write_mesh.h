#pragma once
#include <string>

#include "cranioplan/model/mesh.h"

namespace cranioplan {

enum class MeshFormat { BinarySTL, BinaryPLY, ThreeMF };

/// The format a path's extension asks for (.stl, .ply or .3mf, case-insensitive); throws
/// InputError for other extensions.
MeshFormat mesh_format_for_path(const std::string& path);

/// The bytes `write_mesh` writes (deterministic: the same mesh gives the same bytes, so the
/// SHA-256 of an export can be checked by replaying a plan). A 3MF holds the mesh as the part
/// "implant" in millimetres (write_3mf.h).
std::string encode_mesh(const SkullMesh& mesh, MeshFormat format);
/// Writes the mesh atomically (temporary file in the same folder, then rename). Throws
/// InputError when the file cannot be written.
void write_mesh(const SkullMesh& mesh, const std::string& path, MeshFormat format);
inline void write_mesh(const SkullMesh& mesh, const std::string& path) {
  write_mesh(mesh, path, mesh_format_for_path(path));
}

}  // namespace cranioplan
