#pragma once
// Private: mesh readers kept apart from read_mesh.cpp.
#include <string>
#include <vector>

#include "cranioplan/model/mesh.h"

namespace cranioplan::detail {

/// PLY (ascii, binary little or big endian): the `vertex` element's x, y, z and the `face`
/// element's vertex_indices (or vertex_index) list; other elements and properties are read
/// past. Every count and index is checked against the file's size before it is used, so a
/// truncated or corrupt file is an InputError naming the problem, never a crash.
TriangleSoup read_ply(const std::string& path, const std::string& bytes);

}  // namespace cranioplan::detail
