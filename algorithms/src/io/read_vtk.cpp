// VTK's formats, XML (VTP) and legacy (3D Slicer's default for models), read by VTK's readers
// in a child process.
#include <unistd.h>
#include <vtkFieldData.h>
#include <vtkNew.h>
#include <vtkPolyData.h>
#include <vtkPolyDataReader.h>
#include <vtkSmartPointer.h>
#include <vtkStringArray.h>
#include <vtkXMLPolyDataReader.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <new>
#include <sstream>
#include <string>
#include <string_view>

#include "cranioplan/algorithms/io/file_io.h"
#include "cranioplan/algorithms/io/read_mesh.h"
#include "cranioplan/model/error.h"
#include "file_bytes.h"
#include "isolated_read.h"
#include "mesh_formats.h"
#include "soup_building.h"
#include "vtk_errors.h"

namespace cranioplan::detail {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& problem) {
  throw InputError(path, problem);
}

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

}  // namespace

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

namespace {

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

}  // namespace

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

}  // namespace cranioplan::detail
