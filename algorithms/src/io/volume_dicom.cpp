// DICOM series, read with GDCM. The patient frame is DICOM's own (LPS, mm): a slice's voxel
// (column c, row r) lies at ImagePositionPatient + c·Δc·row_dir + r·Δr·col_dir, where
// ImageOrientationPatient gives row_dir and col_dir and PixelSpacing gives (Δr, Δc). Slices are
// ordered along the normal row_dir × col_dir by their ImagePositionPatient, never by file name
// or InstanceNumber. Pixels are decoded by GDCM (any transfer syntax it decodes: JPEG, JPEG-LS,
// JPEG 2000, RLE, deflate) and mapped to Hounsfield units by each slice's rescale slope and
// intercept.
#include <gdcmImage.h>
#include <gdcmImageReader.h>
#include <gdcmScanner.h>
#include <gdcmTag.h>
#include <gdcmTrace.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>

#include "cranioplan/algorithms/io/read_volume.h"
#include "cranioplan/model/error.h"
#include "file_bytes.h"
#include "isolated_read.h"
#include "volume_formats.h"

namespace cranioplan {
namespace detail {
namespace {

namespace fs = std::filesystem;

const gdcm::Tag kSeriesUid(0x0020, 0x000e), kSeriesDescription(0x0008, 0x103e),
    kModality(0x0008, 0x0060), kRows(0x0028, 0x0010), kColumns(0x0028, 0x0011),
    kOrientation(0x0020, 0x0037), kPosition(0x0020, 0x0032), kPixelSpacing(0x0028, 0x0030),
    kFrames(0x0028, 0x0008), kSeriesNumber(0x0020, 0x0011);

// How messages name the reader when it dies on a file.
const char* const kLibrary = "the DICOM library (GDCM)";

// The most voxels a series may have: 2^31 (8 GiB as floats), four times a 1024 × 1024 × 512 CT.
constexpr double kMaxVoxels = 2147483648.0;

// The most files a folder may hold for a series to be looked for in it.
constexpr size_t kMaxFiles = 200000;

std::string trimmed(const char* s) {
  if (!s) return {};
  std::string t(s);
  while (!t.empty() && (t.back() == ' ' || t.back() == '\0')) t.pop_back();
  size_t a = 0;
  while (a < t.size() && t[a] == ' ') ++a;
  return t.substr(a);
}

// A DS or IS value of several numbers ("a\b\c"); empty when any is not a finite number.
std::vector<double> numbers(const std::string& s) {
  std::vector<double> out;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, '\\')) {
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (end == item.c_str() || !std::isfinite(v)) return {};
    out.push_back(v);
  }
  return out;
}

std::string mm(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.3g mm", v);
  return buf;
}

// One image file of a series, with the geometry its header declares.
struct Slice {
  std::string file;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // ImagePositionPatient
  double along = 0.0;                                  // position · normal
};

// Files of one series that share rows, columns, orientation and spacing: one stack of slices.
struct Stack {
  DicomSeries info;
  Eigen::Vector3d row_dir, col_dir;  // unit; row_dir runs along a row (columns increase)
  double row_spacing = 0, column_spacing = 0;
  std::vector<Slice> slices;
  std::vector<std::string> unplaced;  // files without a position or orientation
  long long frames = 1;
};

struct Scan {
  std::vector<Stack> stacks;
  size_t files = 0;
  std::string first_other;  // a file that is no DICOM image, for the message
};

std::vector<std::string> folder_files(const std::string& path) {
  std::vector<std::string> files;
  std::error_code ec;
  for (fs::recursive_directory_iterator it(path, fs::directory_options::skip_permission_denied, ec),
       end;
       !ec && it != end; it.increment(ec)) {
    if (it.depth() > 8) {
      it.disable_recursion_pending();
      continue;
    }
    std::error_code fec;
    if (!it->is_regular_file(fec)) continue;
    const std::string name = it->path().filename().string();
    if (name == "DICOMDIR" || name.empty() || name[0] == '.') continue;
    files.push_back(it->path().string());
    if (files.size() > kMaxFiles)
      throw InputError(path, "folder holds more than " +
                                 format_count(static_cast<long long>(kMaxFiles)) +
                                 " files; give the folder of one series");
  }
  std::sort(files.begin(), files.end());
  return files;
}

// Memory a header may need beyond what the child has: far more than any real header.
constexpr double kHeaderBudget = 256.0 * 1024.0 * 1024.0;

// Scans one file's header; false when it is no DICOM file GDCM can read, or declares an
// element too large to hold (a malformed length).
bool scan_file(gdcm::Scanner& scanner, const std::string& file) {
  try {
    const AddressSpaceBudget budget(kHeaderBudget);
    return scanner.Scan({file}) && scanner.IsKey(file.c_str());
  } catch (const std::bad_alloc&) {
    return false;
  }
}

// Reads every file's header. `report` hears of each file before GDCM is given it.
Scan scan_folder(const std::string& path, ChildReport& report) {
  // GDCM's own warnings and errors go to the terminal; the messages here say what went wrong.
  gdcm::Trace::WarningOff();
  gdcm::Trace::ErrorOff();
  gdcm::Trace::DebugOff();
  const std::vector<std::string> files = folder_files(path);
  if (files.empty()) throw InputError(path, "folder holds no files (expected a DICOM series)");
  Scan scan;
  scan.files = files.size();
  std::map<std::string, size_t> index;  // stack key → stacks[]
  for (const std::string& file : files) {
    // One file a scan, so that a file the library dies on is known.
    report.reading(file);
    gdcm::Scanner scanner;
    for (const gdcm::Tag& t : {kSeriesUid, kSeriesDescription, kModality, kRows, kColumns,
                               kOrientation, kPosition, kPixelSpacing, kFrames, kSeriesNumber})
      scanner.AddTag(t);
    if (!scan_file(scanner, file)) {
      if (scan.first_other.empty()) scan.first_other = fs::path(file).filename().string();
      continue;
    }
    auto value = [&](const gdcm::Tag& t) { return trimmed(scanner.GetValue(file.c_str(), t)); };
    const std::vector<double> rows = numbers(value(kRows)), cols = numbers(value(kColumns));
    if (rows.size() != 1 || cols.size() != 1 || rows[0] < 1 || cols[0] < 1) {
      if (scan.first_other.empty()) scan.first_other = fs::path(file).filename().string();
      continue;  // no image (a report, a presentation state, a DICOMDIR under another name)
    }
    const std::string uid = value(kSeriesUid);
    const std::vector<double> iop = numbers(value(kOrientation));
    const std::vector<double> ipp = numbers(value(kPosition));
    const std::vector<double> spacing = numbers(value(kPixelSpacing));
    std::ostringstream key;
    key << uid << '|' << rows[0] << 'x' << cols[0];
    for (double x : iop) key << '|' << std::lround(x * 1e4);
    for (double x : spacing) key << '|' << std::lround(x * 1e4);
    auto [it, fresh] = index.emplace(key.str(), scan.stacks.size());
    if (fresh) {
      Stack s;
      s.info.uid = uid;
      s.info.description = value(kSeriesDescription);
      s.info.modality = value(kModality);
      s.info.rows = static_cast<int>(rows[0]);
      s.info.columns = static_cast<int>(cols[0]);
      if (iop.size() == 6) {
        s.row_dir = Eigen::Vector3d(iop[0], iop[1], iop[2]);
        s.col_dir = Eigen::Vector3d(iop[3], iop[4], iop[5]);
      }
      if (spacing.size() == 2) {
        s.row_spacing = spacing[0];
        s.column_spacing = spacing[1];
      }
      const std::vector<double> frames = numbers(value(kFrames));
      if (frames.size() == 1 && frames[0] > 1) s.frames = static_cast<long long>(frames[0]);
      scan.stacks.push_back(std::move(s));
    }
    Stack& s = scan.stacks[it->second];
    if (iop.size() != 6 || ipp.size() != 3) {
      s.unplaced.push_back(fs::path(file).filename().string());
      continue;
    }
    Slice slice;
    slice.file = file;
    slice.position = Eigen::Vector3d(ipp[0], ipp[1], ipp[2]);
    s.slices.push_back(slice);
  }
  for (Stack& s : scan.stacks) {
    s.info.slices = static_cast<long long>(s.slices.size() + s.unplaced.size());
  }
  return scan;
}

long long voxels(const Stack& s) {
  return s.info.slices * s.info.rows * static_cast<long long>(s.info.columns) * s.frames;
}

std::string describe(const DicomSeries& s) {
  std::ostringstream o;
  o << s.uid << " (" << (s.modality.empty() ? "?" : s.modality)
    << (s.description.empty() ? std::string() : ", '" + s.description + "'") << ", " << s.columns
    << "×" << s.rows << "×" << s.slices << ")";
  return o.str();
}

// The stack to read: the one named, else the largest CT stack (the largest of any modality when
// none is CT). Says in `warnings` which it took when there was a choice.
const Stack& choose(const std::string& path, const Scan& scan, const std::string& uid,
                    std::vector<std::string>& warnings) {
  if (scan.stacks.empty())
    throw InputError(
        path,
        "not a readable DICOM series: none of its " +
            format_count(static_cast<long long>(scan.files)) + " files is a DICOM image" +
            (scan.first_other.empty() ? std::string() : " (" + scan.first_other + ": not one)"));
  const Stack* best = nullptr;
  for (const Stack& s : scan.stacks) {
    if (!uid.empty() && s.info.uid != uid) continue;
    const bool ct = s.info.modality == "CT", best_ct = best && best->info.modality == "CT";
    if (!best || (ct && !best_ct) || (ct == best_ct && voxels(s) > voxels(*best))) best = &s;
  }
  if (!best) {
    std::string listing;
    for (const Stack& s : scan.stacks) listing += "\n  " + describe(s.info);
    throw InputError(path, "holds no series " + uid + "; its series are:" + listing);
  }
  if (scan.stacks.size() > 1) {
    std::string others;
    for (const Stack& s : scan.stacks)
      if (&s != best) others += (others.empty() ? "" : ", ") + describe(s.info);
    warnings.push_back(path + ": the folder holds " +
                       format_count(static_cast<long long>(scan.stacks.size())) +
                       " series or stacks; read " + describe(best->info) +
                       (uid.empty() ? std::string(" (the largest CT; choose another by its UID)")
                                    : std::string()) +
                       "; not read: " + others);
  }
  return *best;
}

SampleType sample_type(const std::string& file, const gdcm::PixelFormat& pf) {
  switch (pf.GetScalarType()) {
    case gdcm::PixelFormat::UINT8:
      return SampleType::UInt8;
    case gdcm::PixelFormat::INT8:
      return SampleType::Int8;
    case gdcm::PixelFormat::UINT16:
      return SampleType::UInt16;
    case gdcm::PixelFormat::INT16:
      return SampleType::Int16;
    case gdcm::PixelFormat::UINT32:
      return SampleType::UInt32;
    case gdcm::PixelFormat::INT32:
      return SampleType::Int32;
    case gdcm::PixelFormat::FLOAT32:
      return SampleType::Float32;
    case gdcm::PixelFormat::FLOAT64:
      return SampleType::Float64;
    default:
      throw InputError(
          file, std::string("pixels of type ") + pf.GetScalarTypeAsString() + " are not supported");
  }
}

// One slice's pixels in Hounsfield units (its own rescale applied), rows × columns, column
// fastest.
std::vector<float> read_pixels(const Stack& stack, const std::string& file, ChildReport& report) {
  report.reading(file);
  // The pixels of a slice the size the header says, several times over, and no more.
  const AddressSpaceBudget budget(kHeaderBudget + 32.0 * stack.info.rows * stack.info.columns);
  gdcm::ImageReader reader;
  reader.SetFileName(file.c_str());
  bool read = false;
  try {
    read = reader.Read();
  } catch (const std::bad_alloc&) {
    throw InputError(file, "declares more data than its slice can hold (a malformed length)");
  }
  if (!read) throw InputError(file, "not a readable DICOM image");
  const gdcm::Image& image = reader.GetImage();
  const gdcm::PixelFormat& pf = image.GetPixelFormat();
  if (pf.GetSamplesPerPixel() != 1)
    throw InputError(file, "a colour image (" + std::to_string(pf.GetSamplesPerPixel()) +
                               " samples per pixel) is no CT slice");
  const unsigned* d = image.GetDimensions();
  const unsigned frames = image.GetNumberOfDimensions() > 2 ? d[2] : 1;
  if (frames != 1)
    throw InputError(file, "a multi-frame image (" + std::to_string(frames) +
                               " frames) is not supported; export the series as one file per "
                               "slice");
  if (static_cast<int>(d[0]) != stack.info.columns || static_cast<int>(d[1]) != stack.info.rows)
    throw InputError(file, "its pixel data is " + std::to_string(d[0]) + "×" +
                               std::to_string(d[1]) + " but its header says " +
                               std::to_string(stack.info.columns) + "×" +
                               std::to_string(stack.info.rows));
  const SampleType type = sample_type(file, pf);
  const size_t count = static_cast<size_t>(d[0]) * d[1];
  // Pixel data must hold every pixel. Uncompressed data is measured as stored, before the buffer
  // is made, so a header that claims a vast slice costs no memory.
  const gdcm::ByteValue* stored = image.GetDataElement().GetByteValue();
  const unsigned long length = image.GetBufferLength();
  const unsigned long holds =
      stored ? std::min<unsigned long>(stored->GetLength(), length) : length;
  if (holds < count * sample_size(type))
    throw InputError(file, "its pixel data holds " + format_count(static_cast<long long>(holds)) +
                               " bytes, fewer than its " +
                               format_count(static_cast<long long>(count)) + " pixels need");
  std::string buffer(length, '\0');
  if (!image.GetBuffer(buffer.data()))
    throw InputError(file, "its pixel data could not be decoded (transfer syntax " +
                               std::string(image.GetTransferSyntax().GetString()) + ")");
  std::vector<float> out;
  convert_samples(file, buffer.data(), buffer.size(), count, type, false, out);
  const double slope = image.GetSlope(), intercept = image.GetIntercept();
  if (!std::isfinite(slope) || !std::isfinite(intercept) || slope == 0.0)
    throw InputError(file, "its rescale slope or intercept is not usable");
  if (slope != 1.0 || intercept != 0.0)
    for (float& x : out) x = static_cast<float>(x * slope + intercept);
  if (image.GetPhotometricInterpretation() == gdcm::PhotometricInterpretation::MONOCHROME1)
    throw InputError(file, "MONOCHROME1 (inverted grey) is not a CT slice's interpretation");
  return out;
}

// The slices' geometry checked, and the grid's step from one slice to the next. `along` is each
// slice's distance along the normal, ascending. Throws when slices coincide, are missing, or do
// not lie on one line; warns of a gantry tilt or of spacing that varies (then resampled).
struct SliceAxis {
  Eigen::Vector3d per_mm_along;  // world displacement per mm along the normal (tilt included)
  double step = 0.0;             // the grid's spacing along the normal, mm
  int count = 0;                 // slices of the grid
  bool resample = false;
};

SliceAxis slice_axis(const std::string& path, const Stack& s, const Eigen::Vector3d& normal,
                     std::vector<std::string>& warnings) {
  const std::vector<Slice>& sl = s.slices;
  const size_t n = sl.size();
  const double extent = sl.back().along - sl.front().along;
  std::vector<double> gaps;
  for (size_t k = 1; k < n; ++k) gaps.push_back(sl[k].along - sl[k - 1].along);
  std::vector<double> sorted = gaps;
  std::sort(sorted.begin(), sorted.end());
  const double median = sorted[sorted.size() / 2];
  const double tol = std::max(0.005, 0.005 * median);
  for (size_t k = 0; k < gaps.size(); ++k)
    if (gaps[k] < tol)
      throw InputError(path, "two slices lie at the same position (" +
                                 fs::path(sl[k].file).filename().string() + " and " +
                                 fs::path(sl[k + 1].file).filename().string() +
                                 "): the series holds more than one acquisition; export one");
  SliceAxis axis;
  axis.per_mm_along = (sl.back().position - sl.front().position) / extent;
  // Every slice on the line from the first to the last (a gantry tilt shears the line, but it
  // stays a line).
  const double line_tol = 0.25 * std::min(s.row_spacing, s.column_spacing);
  for (const Slice& x : sl) {
    const Eigen::Vector3d expected =
        sl.front().position + axis.per_mm_along * (x.along - sl.front().along);
    const double off = (x.position - expected).norm();
    if (off > line_tol)
      throw InputError(
          path, "the slices do not lie on one line: " + fs::path(x.file).filename().string() +
                    " stands " + mm(off) + " off the line from the first slice to the last");
  }
  const double largest = sorted.back(), smallest = sorted.front();
  if (largest > 2.0 * median + tol) {
    size_t at = 0;
    while (gaps[at] != largest) ++at;
    throw InputError(path, "slices are missing: a gap of " + mm(largest) + " between " +
                               fs::path(sl[at].file).filename().string() + " and " +
                               fs::path(sl[at + 1].file).filename().string() +
                               " where the series' spacing is " + mm(median));
  }
  const double tilt_deg =
      std::acos(std::clamp(normal.dot(axis.per_mm_along.normalized()), -1.0, 1.0)) * 180.0 / M_PI;
  if (tilt_deg > 0.01) {
    char buf[200];
    std::snprintf(buf, sizeof(buf),
                  ": the slices are tilted %.2f degrees from their normal (gantry tilt); the "
                  "grid is sheared to follow the slices' positions, not resampled",
                  tilt_deg);
    warnings.push_back(path + buf);
  }
  if (largest - smallest <= tol) {
    axis.count = static_cast<int>(n);
    axis.step = extent / static_cast<double>(n - 1);
    return axis;
  }
  axis.resample = true;
  axis.count = static_cast<int>(std::lround(extent / median)) + 1;
  axis.step = extent / (axis.count - 1);
  warnings.push_back(path + ": the slice spacing varies from " + mm(smallest) + " to " +
                     mm(largest) + "; the series was resampled (linearly) onto " +
                     format_count(axis.count) + " slices " + mm(axis.step) + " apart");
  return axis;
}

Volume read_series(const std::string& path, const std::string& series_uid, ChildReport& report) {
  const Scan scan = scan_folder(path, report);
  Volume v;
  const Stack& s = choose(path, scan, series_uid, v.warnings);
  if (s.frames > 1)
    throw InputError(path, "series " + s.info.uid + " is one multi-frame file (" +
                               format_count(s.frames) +
                               " frames); export the series as one file per slice");
  if (!s.unplaced.empty())
    throw InputError(path, s.unplaced.front() +
                               " has no ImagePositionPatient or ImageOrientationPatient: where "
                               "its slices lie in the patient is not known");
  if (s.slices.size() < 2)
    throw InputError(path, "not a readable DICOM series of two or more slices (series " +
                               s.info.uid + " has " + format_count(s.info.slices) + ")");
  if (!(s.row_spacing > 0) || !(s.column_spacing > 0))
    throw InputError(path, "series " + s.info.uid + " has no usable PixelSpacing");
  if (std::abs(s.row_dir.norm() - 1) > 1e-3 || std::abs(s.col_dir.norm() - 1) > 1e-3 ||
      std::abs(s.row_dir.dot(s.col_dir)) > 1e-3)
    throw InputError(path, "series " + s.info.uid +
                               ": ImageOrientationPatient is not two perpendicular unit vectors");
  const Eigen::Vector3d row_dir = s.row_dir.normalized(), col_dir = s.col_dir.normalized();
  const Eigen::Vector3d normal = row_dir.cross(col_dir).normalized();
  Stack sorted = s;
  for (Slice& x : sorted.slices) x.along = x.position.dot(normal);
  std::stable_sort(sorted.slices.begin(), sorted.slices.end(),
                   [](const Slice& a, const Slice& b) { return a.along < b.along; });
  const SliceAxis axis = slice_axis(path, sorted, normal, v.warnings);

  v.dims = {s.info.columns, s.info.rows, axis.count};
  v.directions.col(0) = row_dir * s.column_spacing;
  v.directions.col(1) = col_dir * s.row_spacing;
  v.directions.col(2) = axis.per_mm_along * axis.step;
  v.origin = sorted.slices.front().position;
  const size_t plane = static_cast<size_t>(s.info.columns) * s.info.rows;
  if (static_cast<double>(plane) * axis.count > kMaxVoxels)
    throw InputError(path, "series " + s.info.uid + " would be " + std::to_string(v.dims[0]) + "×" +
                               std::to_string(v.dims[1]) + "×" + std::to_string(v.dims[2]) +
                               " voxels, more than the " +
                               format_count(static_cast<long long>(kMaxVoxels)) +
                               " read; crop the series or export it at a coarser resolution");
  // The first slice is decoded before the volume is made: a header that lies about the slice's
  // size is refused by its pixel data, not believed.
  std::vector<float> first = read_pixels(s, sorted.slices[0].file, report);
  v.data.resize(v.size());
  if (!axis.resample) {
    std::copy(first.begin(), first.end(), v.data.begin());
    for (int k = 1; k < axis.count; ++k) {
      const std::vector<float> px = read_pixels(s, sorted.slices[k].file, report);
      std::copy(px.begin(), px.end(), v.data.begin() + static_cast<std::ptrdiff_t>(k * plane));
    }
  } else {
    // Linear interpolation along the normal between the two slices around each grid slice.
    size_t below = 0;
    std::vector<float> a = std::move(first), b = read_pixels(s, sorted.slices[1].file, report);
    for (int k = 0; k < axis.count; ++k) {
      const double at = sorted.slices.front().along + k * axis.step;
      while (below + 2 < sorted.slices.size() && sorted.slices[below + 1].along < at) {
        ++below;
        a = std::move(b);
        b = read_pixels(s, sorted.slices[below + 1].file, report);
      }
      const double t0 = sorted.slices[below].along, t1 = sorted.slices[below + 1].along;
      const float w = static_cast<float>(std::clamp((at - t0) / (t1 - t0), 0.0, 1.0));
      float* out = v.data.data() + k * plane;
      for (size_t i = 0; i < plane; ++i) out[i] = a[i] + w * (b[i] - a[i]);
    }
  }
  v.description = "DICOM series " + describe(s.info);
  v.frame = "DICOM patient coordinates (LPS)";
  v.kind = VolumeKind::CT;
  if (s.info.modality != "CT") classify_kind(v);
  return v;
}

std::string serialise(const Volume& v) {
  ByteWriter w;
  for (int d : v.dims) w.pod(d);
  w.raw(v.directions.data(), 9 * sizeof(double));
  w.raw(v.origin.data(), 3 * sizeof(double));
  w.pod(static_cast<int>(v.kind));
  w.str(v.description);
  w.str(v.frame);
  w.pod<uint64_t>(v.warnings.size());
  for (const std::string& s : v.warnings) w.str(s);
  w.pod<uint64_t>(v.data.size());
  w.raw(v.data.data(), v.data.size() * sizeof(float));
  return w.take();
}

Volume deserialise_volume(const std::string& bytes) {
  ByteReader r(bytes);
  Volume v;
  for (int& d : v.dims) d = r.pod<int>();
  r.raw(v.directions.data(), 9 * sizeof(double));
  r.raw(v.origin.data(), 3 * sizeof(double));
  v.kind = static_cast<VolumeKind>(r.pod<int>());
  v.description = r.str();
  v.frame = r.str();
  v.warnings.resize(r.pod<uint64_t>());
  for (std::string& s : v.warnings) s = r.str();
  v.data.resize(r.pod<uint64_t>());
  r.raw(v.data.data(), v.data.size() * sizeof(float));
  return v;
}

}  // namespace

// GDCM ends the process on some malformed files (an assertion in its file meta reader, for one):
// the series is read in a child process, whose death becomes a message naming the file.
Volume read_dicom_folder(const std::string& path, const std::string& series_uid) {
  const std::string bytes = run_isolated(path, kLibrary, [&](ChildReport& report) {
    report.result(serialise(read_series(path, series_uid, report)));
  });
  return deserialise_volume(bytes);
}

std::vector<DicomSeries> dicom_series_of(const std::string& folder) {
  const std::string bytes = run_isolated(folder, kLibrary, [&](ChildReport& report) {
    ByteWriter w;
    const Scan scan = scan_folder(folder, report);
    w.pod<uint64_t>(scan.stacks.size());
    for (const Stack& s : scan.stacks) {
      w.str(s.info.uid);
      w.str(s.info.description);
      w.str(s.info.modality);
      w.pod(s.info.rows);
      w.pod(s.info.columns);
      w.pod(s.info.slices);
    }
    report.result(w.take());
  });
  ByteReader r(bytes);
  std::vector<DicomSeries> out(r.pod<uint64_t>());
  for (DicomSeries& s : out) {
    s.uid = r.str();
    s.description = r.str();
    s.modality = r.str();
    s.rows = r.pod<int>();
    s.columns = r.pod<int>();
    s.slices = r.pod<long long>();
  }
  return out;
}

}  // namespace detail

std::vector<DicomSeries> list_dicom_series(const std::string& folder) {
  std::error_code ec;
  if (!std::filesystem::exists(folder, ec)) throw InputError(folder, "does not exist");
  if (!std::filesystem::is_directory(folder, ec)) throw InputError(folder, "is not a folder");
  return detail::dicom_series_of(folder);
}

}  // namespace cranioplan
