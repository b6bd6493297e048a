#include "cranioplan/algorithms/io/read_mesh.h"

#include <unistd.h>
#include <vtkFieldData.h>
#include <vtkNew.h>
#include <vtkPolyData.h>
#include <vtkPolyDataReader.h>
#include <vtkSmartPointer.h>
#include <vtkStringArray.h>
#include <vtkXMLPolyDataReader.h>

#include <algorithm>
#include <cassert>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <new>
#include <sstream>
#include <string_view>

#include "cranioplan/algorithms/geometry/mesh_components.h"
#include "cranioplan/algorithms/io/file_io.h"
#include "cranioplan/model/error.h"
#include "file_bytes.h"
#include "isolated_read.h"
#include "mesh_formats.h"
#include "soup_building.h"
#include "vtk_errors.h"

namespace cranioplan {
namespace {

// ---------------------------------------------------------------------------------------------
// Vertex welding of float coordinates: open-addressing hash on the exact bit patterns.
class FloatWelder {
 public:
  explicit FloatWelder(size_t expected_points) {
    size_t cap = 16;
    while (cap < expected_points * 2) cap <<= 1;
    slots_.assign(cap, -1);
    mask_ = cap - 1;
    keys_.reserve(expected_points * 3);
  }
  int insert(const float* xyz) {
    uint32_t k[3];
    for (int i = 0; i < 3; ++i) {
      const float v = xyz[i] == 0.0f ? 0.0f : xyz[i];  // -0 and +0 weld together
      std::memcpy(&k[i], &v, 4);
    }
    size_t slot = hash(k) & mask_;
    while (true) {
      const int idx = slots_[slot];
      if (idx < 0) {
        const int id = static_cast<int>(keys_.size() / 3);
        keys_.insert(keys_.end(), k, k + 3);
        slots_[slot] = id;
        // At most half the slots in use: the probe above always meets a free slot (a file's
        // triangles may name up to three new points each, more than the size guessed).
        if (2 * (keys_.size() / 3) > slots_.size()) grow();
        return id;
      }
      const uint32_t* e = &keys_[static_cast<size_t>(idx) * 3];
      if (e[0] == k[0] && e[1] == k[1] && e[2] == k[2]) return idx;
      slot = (slot + 1) & mask_;
    }
  }
  std::vector<Eigen::Vector3d> points() const {
    std::vector<Eigen::Vector3d> out(keys_.size() / 3);
    for (size_t i = 0; i < out.size(); ++i) {
      float f[3];
      std::memcpy(f, &keys_[i * 3], 12);
      out[i] = {f[0], f[1], f[2]};
    }
    return out;
  }

 private:
  static size_t hash(const uint32_t* k) {
    uint64_t h = (k[0] * 0x9E3779B97F4A7C15ull) ^ (k[1] * 0xC2B2AE3D27D4EB4Full) ^
                 (k[2] * 0x165667B19E3779F9ull);
    h ^= h >> 29;
    return static_cast<size_t>(h);
  }
  void grow() {
    slots_.assign(slots_.size() * 2, -1);
    mask_ = slots_.size() - 1;
    for (size_t id = 0; id < keys_.size() / 3; ++id) {
      size_t slot = hash(&keys_[id * 3]) & mask_;
      while (slots_[slot] >= 0) slot = (slot + 1) & mask_;
      slots_[slot] = static_cast<int>(id);
    }
  }
  std::vector<int> slots_;
  std::vector<uint32_t> keys_;
  size_t mask_ = 0;
};

[[noreturn]] void fail(const std::string& path, const std::string& problem) {
  throw InputError(path, problem);
}

void check_finite(const std::string& path, const Eigen::Vector3d& p, long long triangle) {
  if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z()))
    fail(path, "triangle " + format_count(triangle + 1) +
                   " has a coordinate that is not a number (NaN or Inf)");
}

// ---------------------------------------------------------------------------------------------
// STL
bool looks_like_text(const std::string& bytes) {
  const size_t n = std::min<size_t>(bytes.size(), 1024);
  for (size_t i = 0; i < n; ++i) {
    const unsigned char c = static_cast<unsigned char>(bytes[i]);
    if (c == 0 || (c < 32 && c != '\n' && c != '\r' && c != '\t' && c != '\f' && c != '\v'))
      return false;
  }
  size_t i = 0;
  while (i < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[i]))) ++i;
  return bytes.compare(i, 5, "solid") == 0;
}

// A binary STL's n triangles, read from the file in blocks of about half a megabyte after the
// `head` already read (the 84-byte header and what follows it): the file is never held whole.
TriangleSoup parse_binary_stl(const std::string& path, detail::FileReader& file,
                              const std::string& head, uint32_t n) {
  FloatWelder welder(static_cast<size_t>(n) / 2 + 16);
  TriangleSoup soup;
  soup.triangles.resize(n);
  constexpr size_t kBlock = 50 * 10000;
  std::vector<char> buffer(kBlock + 50);
  const size_t all = 50 * static_cast<size_t>(n);
  size_t have = std::min(head.size() - 84, all);  // bytes of triangles in the buffer
  std::memcpy(buffer.data(), head.data() + 84, have);
  size_t to_read = all - have;
  uint32_t t = 0;
  while (true) {
    const char* p = buffer.data();
    for (; have >= 50; ++t, p += 50, have -= 50) {
      float xyz[9];
      std::memcpy(xyz, p + 12, 36);
      for (int c = 0; c < 9; ++c)
        if (!std::isfinite(xyz[c]))
          fail(path, "triangle " + format_count(t + 1LL) +
                         " has a coordinate that is not a number (NaN or Inf)");
      for (int v = 0; v < 3; ++v) soup.triangles[t][v] = welder.insert(xyz + 3 * v);
    }
    std::memmove(buffer.data(), p, have);  // a triangle split between two blocks
    if (to_read == 0) break;
    const size_t block = std::min(to_read, kBlock);
    file.read(buffer.data() + have, block);
    have += block;
    to_read -= block;
  }
  assert(t == n && have == 0);
  soup.vertices = welder.points();
  return soup;
}

// A tokenizer over a null-terminated text buffer.
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

TriangleSoup parse_ascii_stl(const std::string& path, const std::string& bytes) {
  TextCursor cur{bytes.c_str(), bytes.c_str() + bytes.size(), 1, {}};
  auto expect = [&](const char* w) {
    const std::string got = cur.word();
    if (got != w)
      fail(path, "ASCII STL: expected '" + std::string(w) + "' on line " + format_count(cur.line) +
                     ", found '" + got.substr(0, 40) + "'");
  };
  cur.word();                                         // "solid"
  while (cur.p < cur.end && *cur.p != '\n') ++cur.p;  // the solid's name
  std::vector<float> coords;
  std::vector<Eigen::Vector3i> tris;
  while (true) {
    if (cur.at_end()) fail(path, "ASCII STL: file ends without 'endsolid'");
    const std::string w = cur.word();
    if (w == "endsolid") break;
    if (w != "facet")
      fail(path, "ASCII STL: expected 'facet' or 'endsolid' on line " + format_count(cur.line) +
                     ", found '" + w.substr(0, 40) + "'");
    expect("normal");
    double d;
    for (int i = 0; i < 3; ++i)
      if (!cur.number(d)) fail(path, "ASCII STL: bad normal on line " + format_count(cur.line));
    expect("outer");
    expect("loop");
    for (int v = 0; v < 3; ++v) {
      expect("vertex");
      for (int i = 0; i < 3; ++i) {
        if (!cur.number(d))
          fail(path, "ASCII STL: bad vertex coordinate on line " + format_count(cur.line));
        if (!std::isfinite(d))
          fail(path, "triangle " + format_count(static_cast<long long>(tris.size()) + 1) +
                         " has a coordinate that is not a number (NaN or Inf)");
        coords.push_back(static_cast<float>(d));
      }
    }
    expect("endloop");
    expect("endfacet");
    tris.emplace_back(0, 0, 0);
  }
  FloatWelder welder(tris.size() / 2 + 16);
  TriangleSoup soup;
  soup.triangles.resize(tris.size());
  for (size_t t = 0; t < tris.size(); ++t)
    for (int v = 0; v < 3; ++v) soup.triangles[t][v] = welder.insert(&coords[(t * 3 + v) * 3]);
  soup.vertices = welder.points();
  return soup;
}

TriangleSoup read_stl(const std::string& path, std::string& format, MeshSpace& space) {
  detail::FileReader file(path);
  const size_t size = file.size();
  std::string bytes(std::min<size_t>(size, 1024), '\0');  // enough to tell binary from text
  file.read(bytes.data(), bytes.size());
  uint32_t n = 0;
  if (size >= 84) std::memcpy(&n, bytes.data() + 80, 4);
  const unsigned long long expected = 84ull + 50ull * n;
  // (A binary STL that declares no triangle has at most 133 bytes, all of them read here.)
  if (size >= 84 && size >= expected && size - expected < 50 &&
      !(n == 0 && looks_like_text(bytes))) {
    if (n == 0) fail(path, "binary STL declares 0 triangles");
    format = "binary STL";
    space = space_in_text(std::string_view(bytes.data(), 80));
    return parse_binary_stl(path, file, bytes, n);
  }
  const size_t head = bytes.size();
  bytes.resize(size);
  file.read(bytes.data() + head, size - head);
  if (looks_like_text(bytes)) {
    format = "ASCII STL";
    space = space_in_text(std::string_view(bytes).substr(0, bytes.find('\n')));
    return parse_ascii_stl(path, bytes);
  }
  // Text that is not ASCII STL (a note, a CSV, an HTML error page saved as .stl): said as such,
  // not read as a binary STL's count of triangles.
  {
    const size_t shown = std::min<size_t>(bytes.size(), 1024);
    bool text = shown > 0;
    for (size_t i = 0; i < shown && text; ++i) {
      const unsigned char c = static_cast<unsigned char>(bytes[i]);
      text = c >= 32 || c == '\n' || c == '\r' || c == '\t';
    }
    if (text) {
      std::string start = bytes.substr(0, std::min<size_t>(bytes.find('\n'), 40));
      fail(path, "not an STL file: it is text (beginning \"" + start +
                     "\"), not a mesh; an ASCII STL begins with \"solid\"");
    }
  }
  if (size < 84) fail(path, "too short for an STL file (" + format_count(size) + " bytes)");
  // A count beyond any scan's mesh (5 GB of triangles) that the file is far from holding is
  // not a truncated STL but another file.
  if (size < expected && n > 100'000'000u && size < expected / 2)
    fail(path, "not an STL file: its header would declare " + format_count(n) +
                   " triangles, and the file holds " + format_count(size) + " bytes");
  if (size < expected)
    fail(path, "file ends after " + format_count((size - 84) / 50) + " of " + format_count(n) +
                   " triangles");
  fail(path, "not an STL file: binary triangle count " + format_count(n) +
                 " does not match the file size of " + format_count(size) +
                 " bytes, and it is not ASCII STL");
}

// ---------------------------------------------------------------------------------------------
// OFF and OBJ (text, polygons are fan-triangulated)
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

// ---------------------------------------------------------------------------------------------
// VTK's XML and legacy readers leak on some malformed files and are not proved against crashing
// on them: they run in a child process (isolated_read.h), which sends the soup back with the
// coordinate system the file declares. `read(declared)` reads the polydata in the child.
template <class Read>
TriangleSoup read_isolated(const std::string& path, const char* reader_name, MeshSpace& space,
                           Read read) {
  const std::string bytes =
      detail::run_isolated(path, reader_name, [&](detail::ChildReport& report) {
        report.reading(path);
        MeshSpace declared = MeshSpace::Undeclared;
        const vtkSmartPointer<vtkPolyData> pd = read(declared);
        const TriangleSoup soup = detail::soup_from_polydata(path, pd);
        detail::ByteWriter w;
        w.pod<uint8_t>(static_cast<uint8_t>(declared));
        w.pod<uint64_t>(soup.vertices.size());
        w.raw(soup.vertices.data(), soup.vertices.size() * sizeof(Eigen::Vector3d));
        w.pod<uint64_t>(soup.triangles.size());
        w.raw(soup.triangles.data(), soup.triangles.size() * sizeof(Eigen::Vector3i));
        report.result(w.take());
      });
  detail::ByteReader r(bytes);
  space = static_cast<MeshSpace>(r.pod<uint8_t>());
  TriangleSoup soup;
  soup.vertices.resize(r.pod<uint64_t>());
  r.raw(soup.vertices.data(), soup.vertices.size() * sizeof(Eigen::Vector3d));
  soup.triangles.resize(r.pod<uint64_t>());
  r.raw(soup.triangles.data(), soup.triangles.size() * sizeof(Eigen::Vector3i));
  return soup;
}

// What a VTP file's pieces declare, summed over them: their points and their cells of every
// kind. Read from the XML before the appended data (raw bytes that may hold anything); VTK reads
// no more than this, failing on an array shorter than its piece declares.
struct VtpDeclared {
  double points = 0.0;
  double cells = 0.0;
};

VtpDeclared vtp_declared(const std::string& bytes) {
  const std::string_view xml = std::string_view(bytes).substr(0, bytes.find("<AppendedData"));
  VtpDeclared d;
  auto attribute = [](std::string_view element, std::string_view name) {
    const std::string key = " " + std::string(name) + "=\"";
    const size_t at = element.find(key);
    if (at == std::string_view::npos) return 0.0;
    const std::string value(element.substr(at + key.size(), 24));
    const double n = std::strtod(value.c_str(), nullptr);
    return std::isfinite(n) && n > 0.0 ? n : 0.0;
  };
  for (size_t at = xml.find("<Piece"); at != std::string_view::npos;
       at = xml.find("<Piece", at + 1)) {
    const std::string_view element = xml.substr(at, xml.find('>', at) - at);
    d.points += attribute(element, "NumberOfPoints");
    for (const char* kind : {"NumberOfVerts", "NumberOfLines", "NumberOfStrips", "NumberOfPolys"})
      d.cells += attribute(element, kind);
  }
  return d;
}

// The memory a read of so many points and cells may take: VTK's arrays (the points, a few
// arrays of point data such as normals, the cells' offsets and connectivity, as double and
// 64-bit ids), the soup made from them and the copy sent back, with room to spare; and the file
// itself a few times (base64 and decompression buffers).
double vtp_read_bytes(const VtpDeclared& d, double file_bytes) {
  return 256.0 * 1024 * 1024 + 4.0 * file_bytes + 256.0 * (d.points + d.cells);
}

// "1 point", "200,000 points".
std::string counted(double n, const char* what) {
  const long long k = static_cast<long long>(std::min(n, 9e18));
  return format_count(k) + " " + what + (k == 1 ? "" : "s");
}

TriangleSoup read_vtp(const std::string& path, const std::string& bytes, MeshSpace& space) {
  // A VTP's arrays are compressed (zlib, LZ4 or LZMA): a file of a megabyte may declare a
  // billion points of zeros, and its size says nothing of what reading it takes. Its pieces'
  // counts do: a file that would take more than half of the machine's memory is refused before
  // it is read, and the reader's child may map no more than those counts need.
  const VtpDeclared declared_counts = vtp_declared(bytes);
  const double budget = vtp_read_bytes(declared_counts, static_cast<double>(bytes.size()));
  const double memory =
      static_cast<double>(::sysconf(_SC_PHYS_PAGES)) * static_cast<double>(::sysconf(_SC_PAGESIZE));
  if (memory > 0.0 && budget > 0.5 * memory)
    fail(path, "declares " + counted(declared_counts.points, "point") + " and " +
                   counted(declared_counts.cells, "cell") +
                   ": reading them would take more than half of this machine's memory (" +
                   format_count(static_cast<long long>(memory / (1024.0 * 1024 * 1024))) +
                   " GB); a skull needs a few million triangles at most (decimate the mesh)");
  return read_isolated(path, "VTK's VTP reader", space, [&](MeshSpace& declared) {
    const detail::AddressSpaceBudget memory_budget(budget);
    vtkNew<vtkXMLPolyDataReader> reader;
    const detail::VtkErrorCatcher errors(reader);
    reader->SetFileName(path.c_str());
    try {
      reader->Update();
    } catch (const std::bad_alloc&) {
      fail(path, "its arrays take more memory than a mesh of " +
                     counted(declared_counts.points, "point") + " and " +
                     counted(declared_counts.cells, "cell") + " does (" +
                     format_count(static_cast<long long>(budget / (1024.0 * 1024))) +
                     " MB): many or large arrays of point or cell data besides the geometry");
    }
    const std::string error = errors.message();
    if (!error.empty()) fail(path, "not a readable VTP file (" + error + ")");
    // 3D Slicer's declaration of the coordinate system: a string array "SPACE".
    if (vtkFieldData* fields = reader->GetOutput()->GetFieldData())
      if (auto* tag = vtkStringArray::SafeDownCast(fields->GetAbstractArray("SPACE")))
        if (tag->GetNumberOfValues() > 0) declared = space_in_text("SPACE=" + tag->GetValue(0));
    return vtkSmartPointer<vtkPolyData>(reader->GetOutput());
  });
}

// A binary legacy VTK file's geometry sections hold exactly the bytes their counts announce.
// VTK's reader does not check that a section is whole: a file cut short reads on past its end
// (and gives other triangles on each run). Checked here, before VTK sees the file: POINTS, then
// VERTICES, LINES, POLYGONS and TRIANGLE_STRIPS as version 4.2 writes them (int32 ids) or as
// 5.1 does (OFFSETS and CONNECTIVITY arrays), up to the first attribute data. ASCII files are
// read by VTK as text, which fails where it ends.
void check_legacy_binary_sections(const std::string& path, const std::string& bytes) {
  size_t at = 0;
  auto next_line = [&]() -> std::vector<std::string> {
    while (at < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[at]))) ++at;
    const size_t eol = std::min(bytes.find('\n', at), bytes.size());
    std::istringstream words(bytes.substr(at, eol - at));
    at = std::min(eol + 1, bytes.size());
    std::vector<std::string> out;
    for (std::string w; words >> w;) out.push_back(w);
    return out;
  };
  auto upper = [](std::string w) {
    for (char& c : w) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    return w;
  };
  auto type_bytes = [&](const std::string& type) -> double {
    const std::string t = upper(type);
    if (t == "BIT" || t == "CHAR" || t == "UNSIGNED_CHAR") return 1;
    if (t == "SHORT" || t == "UNSIGNED_SHORT") return 2;
    if (t == "INT" || t == "UNSIGNED_INT" || t == "FLOAT") return 4;
    if (t == "LONG" || t == "UNSIGNED_LONG" || t == "DOUBLE" || t == "VTKTYPEINT64" ||
        t == "VTKTYPEUINT64")
      return 8;
    return 0;  // unknown: left to VTK
  };
  auto count = [](const std::string& w) {
    char* end = nullptr;
    const double n = std::strtod(w.c_str(), &end);
    return end != w.c_str() && *end == '\0' && n >= 0 ? n : -1.0;
  };
  // Skips `n` bytes of binary data, or fails naming the section.
  auto skip = [&](double n, const std::string& section) {
    if (n > static_cast<double>(bytes.size() - at))
      fail(path, "cut short: its " + section + " announce " +
                     format_count(static_cast<long long>(std::min(n, 9e18))) +
                     " bytes of data, and the file ends " + format_count(bytes.size() - at) +
                     " bytes after their header");
    at += static_cast<size_t>(n);
  };
  // The version line and the title (which may be empty) as they are; then ASCII or BINARY.
  for (int line = 0; line < 2; ++line) at = std::min(bytes.find('\n', at), bytes.size()) + 1;
  if (at >= bytes.size()) return;
  const std::vector<std::string> kind = next_line();
  if (kind.empty() || upper(kind[0]) != "BINARY") return;  // ASCII: VTK's to read
  const std::vector<std::string> dataset = next_line();
  if (dataset.size() < 2 || upper(dataset[0]) != "DATASET" || upper(dataset[1]) != "POLYDATA")
    return;
  while (at < bytes.size()) {
    const std::vector<std::string> w = next_line();
    if (w.empty()) continue;
    const std::string key = upper(w[0]);
    if (key == "METADATA") {  // a block of lines that ends with an empty line
      while (at < bytes.size()) {
        const size_t eol = std::min(bytes.find('\n', at), bytes.size());
        const bool empty = eol == at || (eol == at + 1 && bytes[at] == '\r');
        at = std::min(eol + 1, bytes.size());
        if (empty) break;
      }
      continue;
    }
    if (key == "POINTS" && w.size() >= 3) {
      const double n = count(w[1]), size = type_bytes(w[2]);
      if (n < 0 || size == 0) return;
      skip(n * 3 * size, "POINTS");
      continue;
    }
    if ((key == "VERTICES" || key == "LINES" || key == "POLYGONS" || key == "TRIANGLE_STRIPS") &&
        w.size() >= 3) {
      const double a = count(w[1]), b = count(w[2]);
      if (a < 0 || b < 0) return;
      const size_t before = at;
      const std::vector<std::string> offsets = next_line();
      if (!offsets.empty() && upper(offsets[0]) == "OFFSETS" && offsets.size() >= 2) {
        const double size = type_bytes(offsets[1]);
        if (size == 0) return;
        skip(a * size, key);
        const std::vector<std::string> conn = next_line();
        if (conn.size() < 2 || upper(conn[0]) != "CONNECTIVITY" || type_bytes(conn[1]) == 0) return;
        skip(b * type_bytes(conn[1]), key);
      } else {
        at = before;  // version 4.2: the ids follow at once, int32
        skip(b * 4, key);
      }
      continue;
    }
    return;  // attribute data, or a section this check does not know: VTK's to read
  }
}

// VTK's legacy format, 3D Slicer's default for models (ASCII or binary; Slicer writes version 4.2
// with "3D Slicer output. SPACE=RAS" or "SPACE=LPS" as the header line).
TriangleSoup read_legacy_vtk(const std::string& path, const std::string& bytes, MeshSpace& space) {
  check_legacy_binary_sections(path, bytes);
  // The data is not compressed: its polydata and the soup made from it take a few times the
  // file's bytes. A header that announces more points or cells than the file holds (VTK's
  // reader believes it) fails to allocate at once rather than filling the memory.
  const double budget = 256.0 * 1024 * 1024 + 40.0 * static_cast<double>(bytes.size());
  return read_isolated(path, "VTK's legacy reader", space, [&](MeshSpace& declared) {
    const detail::AddressSpaceBudget memory(budget);
    vtkNew<vtkPolyDataReader> reader;
    const detail::VtkErrorCatcher errors(reader);
    reader->SetFileName(path.c_str());
    if (!reader->IsFilePolyData()) {
      const std::string error = errors.message();
      fail(path,
           "not a VTK polygonal data file" +
               (error.empty() ? std::string(" (another kind of VTK data, e.g. an unstructured "
                                            "grid or an image, or no VTK file)")
                              : " (" + error + ")"));
    }
    reader->Update();
    const std::string error = errors.message();
    if (!error.empty()) fail(path, "not a readable VTK file (" + error + ")");
    if (const char* header = reader->GetHeader()) declared = space_in_text(header);
    return vtkSmartPointer<vtkPolyData>(reader->GetOutput());
  });
}

// The volume the triangles enclose, taken about the vertices' centroid (for a surface with
// holes, as a skull's base and defect are, a point inside keeps the open parts' share small).
double enclosed_volume(const TriangleSoup& soup) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& v : soup.vertices) c += v;
  return signed_volume(soup, c / static_cast<double>(std::max<size_t>(1, soup.vertices.size())));
}

// Drops the pieces that lie more than `far_mm` from the largest piece's bounding box.
void drop_far_pieces(const std::string& path, double far_mm, TriangleSoup& soup, MeshFile& out) {
  const SoupComponents comps = soup_components(soup);
  if (comps.sizes.size() < 2) return;
  const std::vector<PieceBox> boxes = piece_boxes(soup, comps);
  std::vector<bool> keep(comps.sizes.size(), true);
  double farthest = 0.0;
  for (size_t c = 1; c < keep.size(); ++c) {
    const double gap = boxes[c].gap_to(boxes[0]);
    if (gap <= far_mm) continue;
    keep[c] = false;
    ++out.pieces_dropped;
    out.triangles_dropped += comps.sizes[c];
    farthest = std::max(farthest, gap);
  }
  if (out.pieces_dropped == 0) return;
  soup = keep_pieces(soup, comps, keep);
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.0f mm", farthest);
  out.warnings.push_back(
      path + ": " + format_count(out.pieces_dropped) + " piece" +
      (out.pieces_dropped == 1 ? "" : "s") + " of " + format_count(out.triangles_dropped) +
      " triangles lying apart from the skull (up to " + buf + " from it) " +
      (out.pieces_dropped == 1 ? "was" : "were") + " dropped; the skull is its largest piece (" +
      format_count(comps.sizes[0]) + " triangles) and what lies within " +
      std::to_string(static_cast<int>(far_mm)) + " mm of it");
}

}  // namespace

TriangleSoup read_mesh_soup(const std::string& path, std::string* format_out,
                            MeshSpace* space_out) {
  const std::string ext = detail::lower_extension(path);
  std::string format;
  MeshSpace space = MeshSpace::Undeclared;
  TriangleSoup soup;
  // A binary STL is parsed as it is read; the other formats from the whole file.
  const std::string bytes = ext == ".stl" ? std::string() : read_file_bytes(path);
  if (ext == ".stl") {
    soup = read_stl(path, format, space);
  } else if (ext == ".off") {
    format = "OFF";
    soup = read_off(path, bytes);
    space = space_in_comments(bytes);
  } else if (ext == ".obj") {
    format = "OBJ";
    soup = read_obj(path, bytes);
    space = space_in_comments(bytes);
  } else if (ext == ".ply") {
    format = "PLY";
    soup = detail::read_ply(path, bytes);
    space = space_in_text(std::string_view(bytes).substr(0, bytes.find("end_header")));
  } else if (ext == ".vtk") {
    format = "VTK";
    soup = read_legacy_vtk(path, bytes, space);
  } else if (ext == ".vtp") {
    format = "VTP";
    if (bytes.find("<VTKFile") == std::string::npos)
      fail(path, "not a VTP file (no <VTKFile> element)");
    soup = read_vtp(path, bytes, space);
  } else {
    fail(path, "unknown mesh format '" + ext + "' (expected .stl, .ply, .obj, .off, .vtk or .vtp)");
  }
  if (soup.triangles.empty()) fail(path, "contains no triangles");
  if (format != "binary STL" && format != "ASCII STL")  // STL parsers check as they read
    for (size_t t = 0; t < soup.triangles.size(); ++t)
      for (int v = 0; v < 3; ++v)
        check_finite(path, soup.vertices[soup.triangles[t][v]], static_cast<long long>(t));
  if (format_out) *format_out = format;
  if (space_out) *space_out = space;
  return soup;
}

std::vector<std::string> describe_repairs(const SoupRepair& done) {
  std::vector<std::string> out;
  if (done.repeated_dropped > 0)
    out.push_back(format_count(done.repeated_dropped) +
                  " triangles repeat another's three corners (the surface written twice there); "
                  "the copies were dropped");
  const SoupOrientation& o = done.orientation;
  if (o.triangles_turned > 0)
    out.push_back(format_count(o.triangles_turned) + " triangles in " +
                  format_count(o.patches_turned) + (o.patches_turned == 1 ? " patch" : " patches") +
                  " wound against their neighbours (inconsistent winding); they were turned to "
                  "agree");
  if (o.conflicts > 0)
    out.push_back(format_count(o.conflicts) + (o.conflicts == 1 ? " edge where" : " edges where") +
                  " the surface cannot wind one way (a twisted seam); left as read");
  const HoleClosing& h = done.holes;
  if (h.closed > 0) {
    char longest[32];
    std::snprintf(longest, sizeof(longest), "%.1f", h.largest_mm);
    out.push_back(format_count(h.closed) + (h.closed == 1 ? " small hole" : " small holes") +
                  " (up to " + longest + " mm of open edge) closed with " +
                  format_count(h.triangles_added) + " triangles");
  }
  return out;
}

namespace {

// The mesh built in `mesh` (out.mesh or another), the rest of what was read in `out`.
void read_into(const std::string& path, const ReadMeshParams& params, MeshFile& out,
               SkullMesh& mesh) {
  TriangleSoup soup = read_mesh_soup(path, &out.format, &out.space);
  out.triangles_in_file = static_cast<long long>(soup.triangles.size());
  // Into the patient's LPS: x and y negated, a turn about z that keeps the winding.
  if (params.space_from_header && negates_x_and_y(out.space)) {
    for (auto& v : soup.vertices) {
      v.x() = -v.x();
      v.y() = -v.y();
    }
    out.turned_to_lps = true;
  }
  assert(params.unit_mm > 0.0 && std::isfinite(params.unit_mm) && "validated by the caller");
  if (params.unit_mm != 1.0)
    for (auto& v : soup.vertices) v *= params.unit_mm;
  if (params.far_piece_mm > 0.0) drop_far_pieces(path, params.far_piece_mm, soup, out);
  const SoupRepair done = repair_soup(soup, params.repairs);
  out.repeated_dropped = done.repeated_dropped;
  out.triangles_turned = done.orientation.triangles_turned;
  out.patches_turned = done.orientation.patches_turned;
  out.holes_closed = done.holes.closed;
  for (const std::string& sentence : describe_repairs(done))
    out.warnings.push_back(path + ": " + sentence);
  if (params.orient_outward && enclosed_volume(soup) < 0.0) {
    for (auto& t : soup.triangles) std::swap(t[1], t[2]);
    out.turned_outward = true;
    out.warnings.push_back(path +
                           ": the surface was inside out (its triangles wind inward); it was "
                           "turned outward");
  }
  if (params.canonical) make_canonical(soup);

  BuildMeshStats stats;
  build_mesh(soup, mesh, &stats);
  out.degenerate_dropped = stats.degenerate_dropped;
  out.nonmanifold_split = stats.nonmanifold_split;
  if (mesh.n_faces() == 0)
    fail(path, "all " + format_count(out.triangles_in_file) +
                   " triangles have zero area; there is no surface to use");
  if (stats.degenerate_dropped > 0) {
    const std::string msg = format_count(stats.degenerate_dropped) + " of " +
                            format_count(out.triangles_in_file) +
                            " triangles have zero area or a repeated vertex";
    if (params.strict) fail(path, msg);
    out.warnings.push_back(path + ": " + msg + "; they were removed");
  }
  if (stats.nonmanifold_split > 0)
    out.warnings.push_back(path + ": " + format_count(stats.nonmanifold_split) +
                           " triangles share an edge with two or more others (non-manifold); "
                           "they were kept on separate vertices");
}

}  // namespace

MeshFile read_mesh(const std::string& path, const ReadMeshParams& params) {
  MeshFile out;
  read_into(path, params, out, out.mesh);
  return out;
}

MeshFile read_mesh(const std::string& path, const ReadMeshParams& params, SkullMesh& mesh) {
  MeshFile out;
  read_into(path, params, out, mesh);
  return out;
}

}  // namespace cranioplan
