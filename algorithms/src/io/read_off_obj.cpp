// OFF and OBJ, text: polygons fan-triangulated, every index checked.
#include <string>
#include <string_view>
#include <vector>

#include "cranioplan/algorithms/io/file_io.h"
#include "cranioplan/algorithms/io/read_mesh.h"
#include "cranioplan/model/error.h"
#include "mesh_formats.h"
#include "soup_building.h"

namespace cranioplan::detail {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& problem) {
  throw InputError(path, problem);
}

}  // namespace

// The space declared in the file's comment lines ('#'), as 3D Slicer writes it into an OBJ.
MeshSpace space_in_comments(const std::string& bytes) {
  MeshSpace space = MeshSpace::Undeclared;
  for (size_t at = 0; at < bytes.size() && space == MeshSpace::Undeclared;) {
    const size_t eol = std::min(bytes.find('\n', at), bytes.size());
    if (bytes[at] == '#') space = space_in_text(std::string_view(bytes).substr(at, eol - at));
    at = eol + 1;
  }
  return space;
}

TriangleSoup read_off(const std::string& path, const std::string& bytes) {
  // Comments start with '#': blank them out of a copy for simple tokenizing.
  std::string text = bytes;
  for (size_t i = 0; i < text.size(); ++i)
    if (text[i] == '#')
      while (i < text.size() && text[i] != '\n') text[i++] = ' ';
  TextCursor cur{text.c_str(), text.c_str() + text.size(), 1, {}};
  const std::string magic = cur.word();
  if (magic != "OFF") fail(path, "not an OFF file (first word is '" + magic.substr(0, 20) + "')");
  double nv_d, nf_d, ne_d;
  if (!cur.number(nv_d) || !cur.number(nf_d) || !cur.number(ne_d) || nv_d < 0 || nf_d < 0 ||
      nv_d > 1e9 || nf_d > 1e9)
    fail(path, "OFF header must give vertex, face and edge counts");
  const long long nv = static_cast<long long>(nv_d), nf = static_cast<long long>(nf_d);
  TriangleSoup soup;
  soup.vertices.reserve(static_cast<size_t>(std::min<long long>(nv, 1 << 24)));
  for (long long i = 0; i < nv; ++i) {
    Eigen::Vector3d p;
    for (int c = 0; c < 3; ++c)
      if (!cur.number(p[c]))
        fail(path, "file ends or is malformed at vertex " + format_count(i + 1) + " of " +
                       format_count(nv));
    soup.vertices.push_back(p);
  }
  std::vector<int> poly;
  for (long long f = 0; f < nf; ++f) {
    double k;
    if (!cur.number(k) || k < 3 || k > 1e6)
      fail(path,
           "file ends or is malformed at face " + format_count(f + 1) + " of " + format_count(nf));
    poly.resize(static_cast<size_t>(k));
    for (auto& idx : poly) {
      double v;
      if (!cur.number(v)) fail(path, "malformed face " + format_count(f + 1));
      // Checked before the cast: a double beyond int's range has no int value (UB).
      if (!(std::abs(v) <= 2e9))
        fail(path, "face " + format_count(f + 1) + " uses vertex " + cur.last_word() +
                       " but the file has " + format_count(nv) + " vertices");
      idx = static_cast<int>(v);
    }
    // Colour values may follow on the same line.
    while (cur.p < cur.end && *cur.p != '\n') ++cur.p;
    detail::add_polygon(path, poly, static_cast<int>(nv), soup.triangles, "face on line", cur.line);
  }
  return soup;
}

TriangleSoup read_obj(const std::string& path, const std::string& bytes) {
  TriangleSoup soup;
  std::istringstream in(bytes);
  std::string line;
  long long line_no = 0;
  std::vector<int> poly;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.size() < 2) continue;
    if (line[0] == 'v' && line[1] == ' ') {
      Eigen::Vector3d p;
      char* s = line.data() + 2;
      for (int c = 0; c < 3; ++c) {
        char* e = nullptr;
        p[c] = std::strtod(s, &e);
        if (e == s) fail(path, "malformed vertex on line " + format_count(line_no));
        s = e;
      }
      soup.vertices.push_back(p);
    } else if (line[0] == 'f' && line[1] == ' ') {
      poly.clear();
      std::istringstream fs(line.substr(2));
      std::string tok;
      while (fs >> tok) {
        char* e = nullptr;
        const long v = std::strtol(tok.c_str(), &e, 10);
        if (e == tok.c_str() || v == 0)
          fail(path, "malformed face on line " + format_count(line_no));
        // OBJ counts from 1, or back from the last vertex so far with negative numbers.
        if (std::labs(v) > static_cast<long>(soup.vertices.size()))
          fail(path, "face on line " + format_count(line_no) + " uses vertex " + std::to_string(v) +
                         " but only " + format_count(soup.vertices.size()) +
                         " vertices come before it");
        poly.push_back(v > 0 ? static_cast<int>(v - 1)
                             : static_cast<int>(soup.vertices.size()) + static_cast<int>(v));
      }
      if (poly.size() < 3)
        fail(path, "face with fewer than 3 vertices on line " + format_count(line_no));
      detail::add_polygon(path, poly, static_cast<int>(soup.vertices.size()), soup.triangles,
                          "face on line", line_no);
    }
  }
  return soup;
}

}  // namespace cranioplan::detail
