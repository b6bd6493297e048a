#pragma once
// Private: the mesh readers, one format to a file, that read_mesh_soup dispatches to by the
// file's extension. Each throws InputError naming the file and the problem.
#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <string>
#include <vector>

#include "cranioplan/algorithms/io/mesh_space.h"
#include "cranioplan/model/mesh.h"

namespace cranioplan::detail {

/// A tokenizer over a null-terminated text buffer (ASCII STL, OFF, OBJ).
struct TextCursor {
  const char* p;
  const char* end;
  long long line = 1;
  void skip_space() {
    while (p < end && std::isspace(static_cast<unsigned char>(*p))) {
      if (*p == '\n') ++line;
      ++p;
    }
  }
  std::string word() {
    skip_space();
    const char* s = p;
    while (p < end && !std::isspace(static_cast<unsigned char>(*p))) ++p;
    return std::string(s, p);
  }
  bool number(double& out) {
    skip_space();
    char* e = nullptr;
    out = std::strtod(p, &e);
    if (e == p) return false;
    last = std::string(p, std::min<size_t>(static_cast<size_t>(e - p), 40));
    p = e;
    return true;
  }
  const std::string& last_word() const { return last; }
  std::string last;  // the text of the last number read, for messages
  bool at_end() {
    skip_space();
    return p >= end;
  }
};

/// STL, binary or ASCII (by its header and size); `format` says which, `space` the coordinate
/// system a binary header or the solid's name declares.
TriangleSoup read_stl(const std::string& path, std::string& format, MeshSpace& space);
/// OFF and OBJ from their bytes; polygons fan-triangulated.
TriangleSoup read_off(const std::string& path, const std::string& bytes);
TriangleSoup read_obj(const std::string& path, const std::string& bytes);
/// The space declared in a text file's comment lines ('#'), as 3D Slicer writes it into an OBJ.
MeshSpace space_in_comments(const std::string& bytes);
/// VTK XML polydata and legacy VTK, read by VTK's readers in a child process; `space` the
/// coordinate system the file declares.
TriangleSoup read_vtp(const std::string& path, const std::string& bytes, MeshSpace& space);
TriangleSoup read_legacy_vtk(const std::string& path, const std::string& bytes, MeshSpace& space);

/// PLY (ascii, binary little or big endian): the `vertex` element's x, y, z and the `face`
/// element's vertex_indices (or vertex_index) list; other elements and properties are read
/// past. Every count and index is checked against the file's size before it is used, so a
/// truncated or corrupt file is an InputError naming the problem, never a crash.
TriangleSoup read_ply(const std::string& path, const std::string& bytes);

}  // namespace cranioplan::detail
