// PLY, read by hand rather than by VTK's reader: on a truncated binary file, a face whose
// vertex count runs past its line or a header without elements, vtkPLYReader crashed (segfault,
// "free(): invalid pointer") or printed its own errors and returned nothing.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <optional>

#include "cranioplan/model/error.h"
#include "file_bytes.h"
#include "mesh_formats.h"
#include "soup_building.h"

namespace cranioplan::detail {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& problem) {
  throw InputError(path, "PLY: " + problem);
}

std::optional<SampleType> scalar_named(const std::string& name) {
  struct Named {
    const char* name;
    SampleType type;
  };
  static const Named kNames[] = {{"char", SampleType::Int8},      {"int8", SampleType::Int8},
                                 {"uchar", SampleType::UInt8},    {"uint8", SampleType::UInt8},
                                 {"short", SampleType::Int16},    {"int16", SampleType::Int16},
                                 {"ushort", SampleType::UInt16},  {"uint16", SampleType::UInt16},
                                 {"int", SampleType::Int32},      {"int32", SampleType::Int32},
                                 {"uint", SampleType::UInt32},    {"uint32", SampleType::UInt32},
                                 {"float", SampleType::Float32},  {"float32", SampleType::Float32},
                                 {"double", SampleType::Float64}, {"float64", SampleType::Float64}};
  for (const Named& n : kNames)
    if (name == n.name) return n.type;
  return std::nullopt;
}

struct Property {
  std::string name;
  SampleType type = SampleType::Float32;  // of the value, or of a list's items
  std::optional<SampleType> list_count;
};

struct Element {
  std::string name;
  long long count = 0;
  std::vector<Property> properties;
};

enum class Encoding { Ascii, LittleEndian, BigEndian };

struct Header {
  Encoding encoding = Encoding::Ascii;
  std::vector<Element> elements;
  size_t data_start = 0;
};

std::vector<std::string> words_of(const std::string& line) {
  std::vector<std::string> words;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    const size_t s = i;
    while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    if (i > s) words.push_back(line.substr(s, i - s));
  }
  return words;
}

Header parse_header(const std::string& path, const std::string& bytes) {
  Header h;
  bool have_format = false;
  size_t pos = 0;
  long long line_no = 0;
  while (true) {
    const size_t eol = bytes.find('\n', pos);
    if (eol == std::string::npos) fail(path, "the header has no 'end_header' line");
    const std::string line = bytes.substr(pos, eol - pos);
    pos = eol + 1;
    ++line_no;
    const std::vector<std::string> w = words_of(line);
    const std::string where = " on header line " + format_count(line_no);
    if (line_no == 1) {
      if (w.size() != 1 || w[0] != "ply") fail(path, "the file does not start with 'ply'");
      continue;
    }
    if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "end_header") break;
    if (w[0] == "format") {
      if (w.size() != 3 || w[2] != "1.0") fail(path, "unsupported format line" + where);
      if (w[1] == "ascii")
        h.encoding = Encoding::Ascii;
      else if (w[1] == "binary_little_endian")
        h.encoding = Encoding::LittleEndian;
      else if (w[1] == "binary_big_endian")
        h.encoding = Encoding::BigEndian;
      else
        fail(path, "unknown encoding '" + w[1].substr(0, 40) + "'" + where);
      have_format = true;
    } else if (w[0] == "element") {
      char* end = nullptr;
      const long long count = w.size() == 3 ? std::strtoll(w[2].c_str(), &end, 10) : -1;
      if (w.size() != 3 || *end != '\0' || count < 0 || count > 0x7fffffff)
        fail(path, "malformed element line" + where);
      h.elements.push_back({w[1], count, {}});
    } else if (w[0] == "property") {
      if (h.elements.empty()) fail(path, "a property before any element" + where);
      Property p;
      if (w.size() == 5 && w[1] == "list") {
        p.list_count = scalar_named(w[2]);
        const std::optional<SampleType> item = scalar_named(w[3]);
        if (!p.list_count || !item || *p.list_count == SampleType::Float32 ||
            *p.list_count == SampleType::Float64)
          fail(path, "malformed list property" + where);
        p.type = *item;
        p.name = w[4];
      } else if (w.size() == 3 && w[1] != "list") {
        const std::optional<SampleType> t = scalar_named(w[1]);
        if (!t) fail(path, "unknown property type '" + w[1].substr(0, 40) + "'" + where);
        p.type = *t;
        p.name = w[2];
      } else {
        fail(path, "malformed property line" + where);
      }
      h.elements.back().properties.push_back(p);
    } else {
      fail(path, "unknown header keyword '" + w[0].substr(0, 40) + "'" + where);
    }
  }
  if (!have_format) fail(path, "the header has no 'format' line");
  h.data_start = pos;
  return h;
}

// Where a value lies, for messages: "item 5 of 1,000 of element 'vertex'".
struct Place {
  const Element* element;
  long long item;
  std::string text() const {
    return "item " + format_count(item + 1) + " of " + format_count(element->count) +
           " of element '" + element->name.substr(0, 40) + "'";
  }
};

// The data after the header, value by value, bounds-checked.
class Values {
 public:
  Values(const std::string& path, const std::string& bytes, const Header& h)
      : path_(path),
        p_(bytes.data() + h.data_start),
        end_(bytes.data() + bytes.size()),
        encoding_(h.encoding),
        swap_(encoding_ != Encoding::Ascii &&
              (encoding_ == Encoding::LittleEndian) != host_is_little_endian()) {}
  double next(SampleType t, const Place& at) {
    if (encoding_ == Encoding::Ascii) {
      while (p_ < end_ && std::isspace(static_cast<unsigned char>(*p_))) ++p_;
      if (p_ >= end_) fail(path_, "the file ends in " + at.text());
      // The buffer holds more than this token: strtod reads a copy of it.
      const char* s = p_;
      while (p_ < end_ && !std::isspace(static_cast<unsigned char>(*p_))) ++p_;
      const std::string token(s, static_cast<size_t>(std::min<ptrdiff_t>(p_ - s, 64)));
      char* e = nullptr;
      const double v = std::strtod(token.c_str(), &e);
      if (e == token.c_str() || *e != '\0')
        fail(path_, "'" + token.substr(0, 20) + "' is not a number, in " + at.text());
      return v;
    }
    const size_t n = sample_size(t);
    if (static_cast<size_t>(end_ - p_) < n) fail(path_, "the file ends in " + at.text());
    unsigned char b[8];
    std::memcpy(b, p_, n);
    p_ += n;
    if (swap_)
      for (size_t i = 0; i < n / 2; ++i) std::swap(b[i], b[n - 1 - i]);
    return decode(t, b);
  }
  // The most items the rest of the file can hold (each at least `min_size` bytes, or in ASCII
  // at least two characters): a bound for reserving memory from a count the file announces.
  size_t room(size_t min_size) const {
    const size_t left = static_cast<size_t>(end_ - p_);
    return left / (encoding_ == Encoding::Ascii ? 2 : std::max<size_t>(1, min_size));
  }

 private:
  static bool host_is_little_endian() {
    const uint16_t probe = 1;
    unsigned char first;
    std::memcpy(&first, &probe, 1);
    return first == 1;
  }
  template <class T>
  static double as(const unsigned char* b) {
    T v;
    std::memcpy(&v, b, sizeof(T));
    return static_cast<double>(v);
  }
  static double decode(SampleType t, const unsigned char* b) {
    switch (t) {
      case SampleType::Int8:
        return as<int8_t>(b);
      case SampleType::UInt8:
        return as<uint8_t>(b);
      case SampleType::Int16:
        return as<int16_t>(b);
      case SampleType::UInt16:
        return as<uint16_t>(b);
      case SampleType::Int32:
        return as<int32_t>(b);
      case SampleType::UInt32:
        return as<uint32_t>(b);
      case SampleType::Float32:
        return as<float>(b);
      case SampleType::Float64:
        return as<double>(b);
    }
    return 0.0;
  }
  const std::string& path_;
  const char* p_;
  const char* end_;
  Encoding encoding_;
  bool swap_;  // binary, in the other byte order than this machine's
};

int index_of(const Element& e, const char* name) {
  for (size_t i = 0; i < e.properties.size(); ++i)
    if (e.properties[i].name == name) return static_cast<int>(i);
  return -1;
}

}  // namespace

TriangleSoup read_ply(const std::string& path, const std::string& bytes) {
  const Header h = parse_header(path, bytes);
  Values values(path, bytes, h);
  TriangleSoup soup;
  const Element* vertex_element = nullptr;
  // The faces' vertex indices, one after another; face f is [starts[f], starts[f + 1]).
  std::vector<int> indices_read;
  std::vector<size_t> starts{0};
  constexpr long long kMaxPolygon = 1000000;
  for (const Element& e : h.elements) {
    const bool is_vertex = e.name == "vertex", is_face = e.name == "face";
    int xyz[3] = {-1, -1, -1}, indices = -1;
    if (is_vertex) {
      if (vertex_element) fail(path, "two 'vertex' elements");
      vertex_element = &e;
      const char* names[3] = {"x", "y", "z"};
      for (int c = 0; c < 3; ++c) {
        xyz[c] = index_of(e, names[c]);
        if (xyz[c] < 0 || e.properties[xyz[c]].list_count)
          fail(path, "the vertex element has no " + std::string(names[c]) + " coordinate");
      }
      soup.vertices.reserve(std::min<size_t>(static_cast<size_t>(e.count), values.room(12)));
    }
    if (is_face) {
      indices = index_of(e, "vertex_indices");
      if (indices < 0) indices = index_of(e, "vertex_index");
      if (indices < 0 || !e.properties[indices].list_count)
        fail(path, "the face element has no vertex_indices list");
      starts.reserve(std::min<size_t>(static_cast<size_t>(e.count), values.room(13)) + 1);
    }
    Place place{&e, 0};
    for (long long item = 0; item < e.count; ++item) {
      place.item = item;
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      for (size_t k = 0; k < e.properties.size(); ++k) {
        const Property& prop = e.properties[k];
        if (!prop.list_count) {
          const double v = values.next(prop.type, place);
          for (int c = 0; c < 3; ++c)
            if (static_cast<int>(k) == xyz[c]) p[c] = v;
          continue;
        }
        const double n = values.next(*prop.list_count, place);
        if (!(n >= 0 && n <= kMaxPolygon && n == std::floor(n)))
          fail(path, "a list of " + std::to_string(n) + " values in " + place.text());
        const bool keep = static_cast<int>(k) == indices;
        for (long long j = 0; j < static_cast<long long>(n); ++j) {
          const double v = values.next(prop.type, place);
          if (!keep) continue;
          if (!(v == std::floor(v) && std::abs(v) <= 0x7fffffff))
            fail(path, "vertex index " + std::to_string(v) + " in " + place.text());
          indices_read.push_back(static_cast<int>(v));
        }
        if (keep) starts.push_back(indices_read.size());
      }
      if (is_vertex) soup.vertices.push_back(p);
    }
  }
  if (!vertex_element) fail(path, "the file has no vertex element");
  const int nv = static_cast<int>(soup.vertices.size());
  std::vector<int> poly;
  soup.triangles.reserve(starts.size() - 1);
  for (size_t f = 0; f + 1 < starts.size(); ++f) {
    if (starts[f + 1] - starts[f] < 3) continue;
    poly.assign(indices_read.begin() + static_cast<ptrdiff_t>(starts[f]),
                indices_read.begin() + static_cast<ptrdiff_t>(starts[f + 1]));
    add_polygon(path, poly, nv, soup.triangles, "face", static_cast<long long>(f) + 1);
  }
  return soup;
}

}  // namespace cranioplan::detail
