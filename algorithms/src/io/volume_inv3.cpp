// InVesalius 3 projects: a gzip-compressed tar holding main.plist (an XML property list with
// the matrix's dtype, shape (z, y, x) and spacing (x, y, z)) and matrix.dat (raw samples).
#include <cstdlib>
#include <cstring>
#include <map>

#include "cranioplan/algorithms/io/file_io.h"
#include "cranioplan/model/error.h"
#include "file_bytes.h"
#include "volume_formats.h"

namespace cranioplan::detail {
namespace {

std::map<std::string, std::string> untar(const std::string& path, const std::string& tar) {
  std::map<std::string, std::string> files;
  size_t pos = 0;
  while (pos + 512 <= tar.size()) {
    const char* h = tar.data() + pos;
    if (h[0] == '\0') break;  // end-of-archive block
    std::string name(h, strnlen(h, 100));
    const std::string prefix(h + 345, strnlen(h + 345, 155));
    if (!prefix.empty() && std::memcmp(h + 257, "ustar", 5) == 0) name = prefix + "/" + name;
    char size_field[13] = {0};
    std::memcpy(size_field, h + 124, 12);
    char* end = nullptr;
    const unsigned long long size = std::strtoull(size_field, &end, 8);
    if (end == size_field) throw InputError(path, "corrupt archive entry '" + name + "'");
    const char type = h[156];
    pos += 512;
    if (size > tar.size() - pos)
      throw InputError(path, "archive entry '" + name + "' is cut off (" +
                                 format_count(static_cast<long long>(size)) + " bytes announced)");
    if (type == '0' || type == '\0') files[name] = tar.substr(pos, size);
    pos += (size + 511) / 512 * 512;
  }
  return files;
}

// A minimal property-list reader: finds <key>K</key> followed by its value element.
struct Plist {
  std::string xml;
  // The text after <key>key</key> up to the end of the next value element, searched within
  // [from, to).
  size_t find_key(const std::string& key, size_t from = 0) const {
    const std::string tag = "<key>" + key + "</key>";
    const size_t p = xml.find(tag, from);
    return p == std::string::npos ? p : p + tag.size();
  }
  std::string element_text(size_t from, const std::string& element) const {
    const size_t a = xml.find("<" + element + ">", from);
    const size_t b = xml.find("</" + element + ">", a);
    if (a == std::string::npos || b == std::string::npos) return {};
    return xml.substr(a + element.size() + 2, b - a - element.size() - 2);
  }
  // The text of the element that comes next after `from` (a key's value), whatever its type.
  std::string next_value(size_t from) const {
    const size_t a = xml.find('<', from);
    if (a == std::string::npos) return {};
    const size_t b = xml.find('>', a);
    if (b == std::string::npos || xml[b - 1] == '/') return {};
    const std::string tag = xml.substr(a + 1, b - a - 1);
    const size_t c = xml.find("</" + tag + ">", b);
    return c == std::string::npos ? std::string() : xml.substr(b + 1, c - b - 1);
  }
  std::vector<double> numbers_in_array(size_t from) const {
    std::vector<double> out;
    const size_t end = xml.find("</array>", from);
    size_t p = from;
    while (true) {
      const size_t ri = xml.find("<real>", p), ii = xml.find("<integer>", p);
      const size_t q = std::min(ri, ii);
      if (q == std::string::npos || q > end) break;
      const size_t start = xml.find('>', q) + 1;
      out.push_back(std::strtod(xml.c_str() + start, nullptr));
      p = start;
    }
    return out;
  }
};

}  // namespace

Volume read_inv3(const std::string& path) {
  const std::string packed = read_file_bytes(path);
  if (packed.size() < 2 || static_cast<unsigned char>(packed[0]) != 0x1f ||
      static_cast<unsigned char>(packed[1]) != 0x8b)
    throw InputError(path, "not an InVesalius project (not gzip-compressed)");
  const auto files = untar(path, gunzip(path, packed.data(), packed.size()));
  const std::string* plist_text = nullptr;
  std::string dir;
  for (const auto& [name, content] : files) {
    if (name == "main.plist" ||
        (name.size() > 11 && name.substr(name.size() - 11) == "/main.plist")) {
      plist_text = &content;
      dir = name.substr(0, name.size() - 10);
    }
  }
  if (!plist_text) throw InputError(path, "not an InVesalius project (no main.plist inside)");
  const Plist plist{*plist_text};
  const size_t matrix = plist.find_key("matrix");
  if (matrix == std::string::npos) throw InputError(path, "main.plist has no 'matrix' entry");
  const std::string dtype = plist.element_text(plist.find_key("dtype", matrix), "string");
  const std::string filename = plist.element_text(plist.find_key("filename", matrix), "string");
  const size_t shape_at = plist.find_key("shape", matrix);
  const size_t spacing_at = plist.find_key("spacing");
  if (dtype.empty() || filename.empty() || shape_at == std::string::npos ||
      spacing_at == std::string::npos)
    throw InputError(path, "main.plist lacks the matrix dtype, filename, shape or spacing");
  // InVesalius's "orientation" of the series it was made from: 1 axial, 2 coronal, 3 sagittal
  // (constants.py); the matrix's layout differs for each, and only the axial one is read.
  const size_t orientation_at = plist.find_key("orientation");
  if (orientation_at != std::string::npos) {
    const std::string named = plist.next_value(orientation_at);
    if (!named.empty() && named != "1" && named != "AXIAL")
      throw InputError(path, "the project was made from a " +
                                 std::string(named == "2" || named == "CORONAL" ? "coronal"
                                             : named == "3" || named == "SAGITTAL"
                                                 ? "sagittal"
                                                 : "non-axial (" + named + ")") +
                                 " series; only projects of axial series are read (import the "
                                 "DICOM series itself)");
  }
  const std::vector<double> shape = plist.numbers_in_array(shape_at);
  const std::vector<double> spacing = plist.numbers_in_array(spacing_at);
  if (shape.size() != 3 || spacing.size() != 3)
    throw InputError(path, "main.plist: matrix shape and spacing must have 3 values each");
  for (int a = 0; a < 3; ++a) {
    if (shape[a] < 1 || shape[a] > 1e5)
      throw InputError(
          path, "main.plist: matrix shape value " + std::to_string(shape[a]) + " is out of range");
    if (!(spacing[a] > 0) || spacing[a] > 1e3)
      throw InputError(path, "main.plist: spacing must be positive");
  }
  SampleType type;
  if (dtype == "int16")
    type = SampleType::Int16;
  else if (dtype == "uint16")
    type = SampleType::UInt16;
  else if (dtype == "uint8")
    type = SampleType::UInt8;
  else if (dtype == "int8")
    type = SampleType::Int8;
  else if (dtype == "int32")
    type = SampleType::Int32;
  else if (dtype == "float32")
    type = SampleType::Float32;
  else if (dtype == "float64")
    type = SampleType::Float64;
  else
    throw InputError(path, "main.plist: unsupported matrix dtype '" + dtype + "'");

  const auto data_it = files.find(dir + filename);
  if (data_it == files.end())
    throw InputError(path, "the project names '" + filename + "' but the archive lacks it");
  Volume v;
  // shape is (slices, rows, columns) = (k, j, i); spacing is (x, y, z).
  v.dims = {static_cast<int>(shape[2]), static_cast<int>(shape[1]), static_cast<int>(shape[0])};
  // InVesalius's layout of an axial series (docs/FRAMES.md, from its source): slices in
  // GDCM's IPPSorter order (k towards the head), each slice's rows reversed from DICOM's
  // (row 0 of the matrix is DICOM's last row, the back of the head), columns as in DICOM
  // (towards the patient's left). j is flipped back so that the frame is the patient's LPS;
  // without the flip every mesh would be the mirror image of the patient. The project keeps
  // no ImagePositionPatient: the first voxel of the first slice lies at x = 0, z = 0.
  v.directions = Eigen::Vector3d(spacing[0], -spacing[1], spacing[2]).asDiagonal();
  v.origin = Eigen::Vector3d(0.0, spacing[1] * (shape[1] - 1), 0.0);
  v.frame = "InVesalius project (axial series in InVesalius's layout), LPS; origin not stored";
  convert_samples(path + " (" + filename + ")", data_it->second.data(), data_it->second.size(),
                  v.size(), type, false, v.data);
  if (data_it->second.size() != v.size() * sample_size(type))
    throw InputError(path, filename + " holds " +
                               format_count(static_cast<long long>(data_it->second.size())) +
                               " bytes but main.plist announces " +
                               format_count(static_cast<long long>(v.size() * sample_size(type))));
  const size_t name_at = plist.find_key("name");
  const size_t modality_at = plist.find_key("modality");
  const std::string modality =
      modality_at == std::string::npos ? "" : plist.element_text(modality_at, "string");
  v.description = "InVesalius project '" +
                  (name_at == std::string::npos ? "" : plist.element_text(name_at, "string")) + "'";
  if (modality == "CT" || modality.empty())
    v.kind = VolumeKind::CT;
  else
    classify_kind(v);
  return v;
}

}  // namespace cranioplan::detail
