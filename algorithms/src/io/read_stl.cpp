// STL, binary and ASCII: a binary file parsed as it is read (never held whole), its float
// vertices welded on their exact bit patterns.
#include <algorithm>
#include <cassert>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "cranioplan/algorithms/io/file_io.h"
#include "cranioplan/algorithms/io/read_mesh.h"
#include "cranioplan/model/error.h"
#include "file_bytes.h"
#include "mesh_formats.h"

namespace cranioplan::detail {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& problem) {
  throw InputError(path, problem);
}

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

}  // namespace

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

}  // namespace cranioplan::detail
