// NRRD (teem) volumes: attached or detached data, raw or gzip, `space directions` (possibly
// oblique) and `space origin`; `spacings` when no directions are given.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <optional>
#include <sstream>

#include "cranioplan/algorithms/io/file_io.h"
#include "cranioplan/model/error.h"
#include "file_bytes.h"
#include "volume_formats.h"

namespace cranioplan::detail {
namespace {

std::string trim(const std::string& s) {
  size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  return s.substr(a, b - a);
}

SampleType parse_type(const std::string& path, std::string t) {
  static const std::map<std::string, SampleType> types = {
      {"signed char", SampleType::Int8},    {"int8", SampleType::Int8},
      {"int8_t", SampleType::Int8},         {"uchar", SampleType::UInt8},
      {"unsigned char", SampleType::UInt8}, {"uint8", SampleType::UInt8},
      {"uint8_t", SampleType::UInt8},       {"short", SampleType::Int16},
      {"short int", SampleType::Int16},     {"signed short", SampleType::Int16},
      {"int16", SampleType::Int16},         {"int16_t", SampleType::Int16},
      {"ushort", SampleType::UInt16},       {"unsigned short", SampleType::UInt16},
      {"uint16", SampleType::UInt16},       {"uint16_t", SampleType::UInt16},
      {"int", SampleType::Int32},           {"signed int", SampleType::Int32},
      {"int32", SampleType::Int32},         {"int32_t", SampleType::Int32},
      {"uint", SampleType::UInt32},         {"unsigned int", SampleType::UInt32},
      {"uint32", SampleType::UInt32},       {"uint32_t", SampleType::UInt32},
      {"float", SampleType::Float32},       {"double", SampleType::Float64}};
  std::transform(t.begin(), t.end(), t.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  const auto it = types.find(t);
  if (it == types.end()) throw InputError(path, "NRRD type '" + t + "' is not supported");
  return it->second;
}

// "(a,b,c)" → vector; "none" → empty.
std::vector<Eigen::Vector3d> parse_vectors(const std::string& path, const std::string& field,
                                           const std::string& text) {
  std::vector<Eigen::Vector3d> out;
  size_t p = 0;
  while ((p = text.find_first_not_of(" \t", p)) != std::string::npos) {
    if (text.compare(p, 4, "none") == 0) {
      p += 4;
      continue;
    }
    if (text[p] != '(') throw InputError(path, "NRRD field '" + field + "' is malformed");
    const size_t q = text.find(')', p);
    if (q == std::string::npos) throw InputError(path, "NRRD field '" + field + "' is malformed");
    std::string inner = text.substr(p + 1, q - p - 1);
    std::replace(inner.begin(), inner.end(), ',', ' ');
    std::istringstream in(inner);
    Eigen::Vector3d v;
    if (!(in >> v.x() >> v.y() >> v.z()) || !v.allFinite())
      throw InputError(path, "NRRD field '" + field + "' must hold 3 numbers per vector");
    out.push_back(v);
    p = q + 1;
  }
  return out;
}

// The NRRD `space` (its name or abbreviation) as signs of LPS's axes; none for spaces that are
// no patient's (scanner-xyz, 3D-right-handed) or absent.
std::optional<Eigen::Vector3d> patient_space_signs(std::string space) {
  std::transform(space.begin(), space.end(), space.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (space == "left-posterior-superior" || space == "lps") return Eigen::Vector3d(1, 1, 1);
  if (space == "right-anterior-superior" || space == "ras") return Eigen::Vector3d(-1, -1, 1);
  if (space == "left-anterior-superior" || space == "las") return Eigen::Vector3d(1, -1, 1);
  return std::nullopt;
}

void frame_from_space(const std::string& path, const std::string& space, bool patient_frame,
                      Volume& v) {
  const std::optional<Eigen::Vector3d> signs = patient_space_signs(space);
  if (!signs) {
    v.frame = space.empty() ? std::string("none declared (NRRD without 'space')")
                            : "NRRD space '" + space + "' (no patient's)";
    v.frame += "; read as LPS";
    v.warnings.push_back(path + ": the file declares " +
                         (space.empty() ? std::string("no patient space")
                                        : "the space '" + space + "', which is no patient's") +
                         ", so the patient's left and right are not known from it; its axes "
                         "were read as left, posterior, superior");
    return;
  }
  v.frame = "NRRD space " + space;
  if (patient_frame && *signs != Eigen::Vector3d(1, 1, 1)) {
    flip_axes(v, *signs);
    v.frame += ", turned to LPS";
  }
}

// A segment of a 3D Slicer segmentation (.seg.nrrd): its fields SegmentN_*.
struct Segment {
  std::string id, name;
  int label = 1;
};

std::vector<Segment> segments_of(const std::string& path,
                                 const std::map<std::string, std::string>& custom) {
  std::vector<Segment> out;
  for (int n = 0;; ++n) {
    const std::string prefix = "Segment" + std::to_string(n) + "_";
    const auto id = custom.find(prefix + "ID");
    if (id == custom.end()) break;
    Segment s;
    s.id = id->second;
    const auto name = custom.find(prefix + "Name");
    s.name = name == custom.end() ? s.id : name->second;
    const auto label = custom.find(prefix + "LabelValue");
    if (label != custom.end()) {
      char* end = nullptr;
      const long v = std::strtol(label->second.c_str(), &end, 10);
      if (end == label->second.c_str() || v < 1)
        throw InputError(
            path, "segment '" + s.name + "' has no usable label value ('" + label->second + "')");
      s.label = static_cast<int>(v);
    }
    out.push_back(s);
  }
  return out;
}

// A Slicer segmentation as the bone's mask: the segment named bone, skull or cranium (any
// case), or the only segment; its label value's samples 1, the others 0.
void keep_bone_segment(const std::string& path, const std::map<std::string, std::string>& custom,
                       Volume& v) {
  const std::vector<Segment> segments = segments_of(path, custom);
  const Segment* bone = segments.size() == 1 ? &segments[0] : nullptr;
  for (const Segment& s : segments) {
    std::string n = s.name;
    std::transform(n.begin(), n.end(), n.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (!bone && (n.find("bone") != std::string::npos || n.find("skull") != std::string::npos ||
                  n.find("cranium") != std::string::npos))
      bone = &s;
  }
  if (!bone) {
    std::string names;
    for (const Segment& s : segments) names += (names.empty() ? "'" : ", '") + s.name + "'";
    throw InputError(path, "the segmentation holds " + std::to_string(segments.size()) +
                               " segments (" + names +
                               ") and none is named bone, skull or cranium: rename the skull's "
                               "segment in 3D Slicer");
  }
  long long kept = 0;
  for (float& x : v.data) {
    x = std::lround(x) == bone->label ? 1.0f : 0.0f;
    kept += x > 0.0f;
  }
  if (kept == 0)
    throw InputError(
        path, "segment '" + bone->name + "' (label " + std::to_string(bone->label) + ") is empty");
  v.kind = VolumeKind::Mask;
  v.description = "3D Slicer segmentation, segment '" + bone->name + "' of " +
                  std::to_string(segments.size()) + " (" + v.description + ")";
  if (segments.size() > 1)
    v.warnings.push_back(path + ": the segment '" + bone->name + "' is read as the skull; the " +
                         std::to_string(segments.size() - 1) + " others are left out");
}

}  // namespace

namespace {

// A NRRD header: its fields (keys in lower case), its key:=value pairs (Slicer's segment
// fields), and where the attached data starts.
struct NrrdHeader {
  std::map<std::string, std::string> fields, custom;
  size_t data_pos = 0;
  bool done = false;  ///< ended by a blank line

  std::string field(const std::string& k) const {
    auto it = fields.find(k);
    return it == fields.end() ? std::string() : it->second;
  }
  std::string data_file() const {
    return !field("data file").empty() ? field("data file") : field("datafile");
  }
};

NrrdHeader parse_nrrd_header(const std::string& path, const std::string& bytes) {
  if (bytes.compare(0, 4, "NRRD") != 0) throw InputError(path, "not a NRRD file (no 'NRRD' magic)");
  NrrdHeader h;
  size_t pos = bytes.find('\n');
  if (pos == std::string::npos) throw InputError(path, "NRRD header is not terminated");
  ++pos;
  while (pos < bytes.size()) {
    size_t eol = bytes.find('\n', pos);
    if (eol == std::string::npos) eol = bytes.size();
    std::string line = bytes.substr(pos, eol - pos);
    pos = eol + 1;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) {
      h.done = true;
      break;
    }
    if (line[0] == '#') continue;
    const size_t assign = line.find(":=");
    if (assign != std::string::npos) {
      h.custom[line.substr(0, assign)] = line.substr(assign + 2);
      continue;
    }
    const size_t colon = line.find(": ");
    if (colon == std::string::npos) continue;  // unknown lines
    std::string key = line.substr(0, colon);
    std::transform(key.begin(), key.end(), key.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    h.fields[key] = trim(line.substr(colon + 2));
  }
  h.data_pos = pos;
  if (!h.done && h.data_file().empty())
    throw InputError(path, "NRRD header does not end with a blank line before the data");
  if (h.field("dimension") != "3") {
    if (h.custom.count("Segment0_ID"))
      throw InputError(path,
                       "a segmentation of overlapping segments (layers) is not read: in 3D Slicer, "
                       "export the bone's segment alone, or save the segments without overlap");
    throw InputError(path, "only 3-dimensional NRRD volumes are supported (dimension: " +
                               h.field("dimension") + ")");
  }
  if (h.field("type").empty() || h.field("sizes").empty() || h.field("encoding").empty())
    throw InputError(path, "NRRD header lacks type, sizes or encoding");
  return h;
}

// The grid's sizes, axes and origin from the header into `v`.
void nrrd_geometry(const std::string& path, const NrrdHeader& h, Volume& v) {
  std::istringstream sizes(h.field("sizes"));
  for (int a = 0; a < 3; ++a) {
    long long s = 0;
    if (!(sizes >> s) || s < 1 || s > 100000)
      throw InputError(path, "NRRD sizes must be 3 positive numbers ('" + h.field("sizes") + "')");
    v.dims[a] = static_cast<int>(s);
  }
  if (!h.field("space directions").empty()) {
    const auto dirs = parse_vectors(path, "space directions", h.field("space directions"));
    if (dirs.size() != 3)
      throw InputError(path, "NRRD 'space directions' must give 3 vectors for a 3D volume");
    for (int a = 0; a < 3; ++a) v.directions.col(a) = dirs[a];
  } else if (!h.field("spacings").empty()) {
    std::istringstream in(h.field("spacings"));
    Eigen::Vector3d s;
    if (!(in >> s.x() >> s.y() >> s.z()) || !(s.array() > 0).all())
      throw InputError(path, "NRRD 'spacings' must be 3 positive numbers");
    v.directions = s.asDiagonal();
  }
  if (!h.field("space origin").empty()) {
    const auto o = parse_vectors(path, "space origin", h.field("space origin"));
    if (o.size() != 1) throw InputError(path, "NRRD 'space origin' must be one vector");
    v.origin = o[0];
  }
}

// The samples (attached after the header in `bytes`, or in the detached data file), raw or
// gzip, into v.data.
void read_nrrd_samples(const std::string& path, const NrrdHeader& h, const std::string& bytes,
                       SampleType type, Volume& v) {
  const std::string encoding = h.field("encoding");
  const bool big_endian = h.field("endian") == "big";
  std::string detached;
  const char* data = nullptr;
  size_t available = 0;
  if (const std::string data_file = h.data_file(); !data_file.empty()) {
    std::filesystem::path dp(data_file);
    if (dp.is_relative()) dp = std::filesystem::path(path).parent_path() / dp;
    detached = read_file_bytes(dp.string());
    data = detached.data();
    available = detached.size();
  } else {
    data = bytes.data() + h.data_pos;
    available = bytes.size() - std::min(h.data_pos, bytes.size());
  }
  const size_t need = v.size() * sample_size(type);
  if (encoding == "gzip" || encoding == "gz") {
    // Deflate expands at most 1032 times: data that cannot hold the samples the header
    // announces (a fuzzed header asks for terabytes) is inflated only to say how much it holds.
    if (need > available * 1032 + (size_t{1} << 16)) {
      const size_t held = gunzip_each(path, data, available, need, [](const char*, size_t) {});
      if (held < need)  // throws the message for too few bytes, converting nothing
        convert_samples(path, data, held, v.size(), type, big_endian, v.data);
    }
    // Converted as it is inflated: the inflated samples are never held whole, only the floats
    // they become (docs/decisions/0028-speed-history.md).
    SampleStream samples(path, v.size(), type, big_endian, v.data);
    gunzip_each(path, data, available, need,
                [&](const char* piece, size_t n) { samples.add(piece, n); });
    samples.finish();
  } else if (encoding == "raw") {
    // "byte skip: -1" means the data is the last `need` bytes; otherwise sizes must agree.
    if (h.field("byte skip") == "-1" && available > need) {
      data += available - need;
      available = need;
    } else if (available > need) {
      throw InputError(path, "the header announces " + format_count(static_cast<long long>(need)) +
                                 " bytes of samples but the data holds " +
                                 format_count(static_cast<long long>(available)));
    }
    convert_samples(path, data, available, v.size(), type, big_endian, v.data);
  } else {
    throw InputError(path, "NRRD encoding '" + encoding + "' is not supported (use raw or gzip)");
  }
}

}  // namespace

Volume read_nrrd(const std::string& path, bool patient_frame) {
  const std::string bytes = read_file_bytes(path);
  const NrrdHeader h = parse_nrrd_header(path, bytes);
  const SampleType type = parse_type(path, h.field("type"));
  Volume v;
  nrrd_geometry(path, h, v);
  frame_from_space(path, h.field("space"), patient_frame, v);
  read_nrrd_samples(path, h, bytes, type, v);
  std::ostringstream d;
  d << "NRRD " << v.dims[0] << "×" << v.dims[1] << "×" << v.dims[2] << " " << h.field("type");
  v.description = d.str();
  if (h.custom.count("Segment0_ID"))
    keep_bone_segment(path, h.custom, v);
  else
    classify_kind(v);
  return v;
}

}  // namespace cranioplan::detail
