#pragma once
// Private: mesh readers kept apart from read_mesh.cpp, and what they share with it.
#include <string>
#include <vector>

#include "cranioplan/model/mesh.h"

namespace cranioplan::detail {

/// Appends `poly` (0-based vertex indices) fan-triangulated to `tris`. Throws InputError when
/// an index is outside [0, nv); `what` and `number` name the face in the message ("face on
/// line", 12).
void add_polygon(const std::string& path, const std::vector<int>& poly, int nv,
                 std::vector<Eigen::Vector3i>& tris, const char* what, long long number);

/// PLY (ascii, binary little or big endian): the `vertex` element's x, y, z and the `face`
/// element's vertex_indices (or vertex_index) list; other elements and properties are read
/// past. Every count and index is checked against the file's size before it is used, so a
/// truncated or corrupt file is an InputError naming the problem, never a crash.
TriangleSoup read_ply(const std::string& path, const std::string& bytes);

}  // namespace cranioplan::detail
