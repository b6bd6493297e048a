#include "cranioplan/algorithms/io/read_volume.h"

#include <Eigen/LU>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <new>

#include "cranioplan/model/error.h"
#include "cranioplan/model/parallel.h"
#include "file_bytes.h"
#include "volume_formats.h"

namespace cranioplan {
namespace detail {

namespace {

template <class T>
void convert_typed(const char* data, size_t count, bool swap, float* out) {
  for (size_t i = 0; i < count; ++i) {
    unsigned char b[sizeof(T)];
    std::memcpy(b, data + i * sizeof(T), sizeof(T));
    if (swap)
      for (size_t k = 0; k < sizeof(T) / 2; ++k) std::swap(b[k], b[sizeof(T) - 1 - k]);
    T v;
    std::memcpy(&v, b, sizeof(T));
    out[i] = static_cast<float>(v);
  }
}

// `count` samples of `type` at `data` as floats in `out`.
void convert_range(SampleType type, bool big_endian, const char* data, size_t count, float* out) {
  const bool swap = big_endian;  // this program runs on little-endian machines
  switch (type) {
    case SampleType::Int8:
      return convert_typed<int8_t>(data, count, false, out);
    case SampleType::UInt8:
      return convert_typed<uint8_t>(data, count, false, out);
    case SampleType::Int16:
      return convert_typed<int16_t>(data, count, swap, out);
    case SampleType::UInt16:
      return convert_typed<uint16_t>(data, count, swap, out);
    case SampleType::Int32:
      return convert_typed<int32_t>(data, count, swap, out);
    case SampleType::UInt32:
      return convert_typed<uint32_t>(data, count, swap, out);
    case SampleType::Float32:
      return convert_typed<float>(data, count, swap, out);
    case SampleType::Float64:
      return convert_typed<double>(data, count, swap, out);
  }
}

[[noreturn]] void too_few_bytes(const std::string& path, size_t count, size_t need,
                                size_t available) {
  throw InputError(path, "the header announces " + format_count(static_cast<long long>(count)) +
                             " samples (" + format_count(static_cast<long long>(need)) +
                             " bytes) but the data holds only " +
                             format_count(static_cast<long long>(available)) + " bytes");
}

// Integers are finite; floats are checked.
void check_finite(const std::string& path, SampleType type, const std::vector<float>& out) {
  if (type != SampleType::Float32 && type != SampleType::Float64) return;
  for (size_t i = 0; i < out.size(); ++i)
    if (!std::isfinite(out[i]))
      throw InputError(path, "sample " + format_count(static_cast<long long>(i)) +
                                 " is not a number (NaN or Inf)");
}

}  // namespace

void convert_samples(const std::string& path, const char* data, size_t available, size_t count,
                     SampleType type, bool big_endian, std::vector<float>& out) {
  const size_t size = sample_size(type), need = count * size;
  if (available < need) too_few_bytes(path, count, need, available);
  out.resize(count);
  parallel_for(count, [&](size_t begin, size_t end) {
    convert_range(type, big_endian, data + begin * size, end - begin, out.data() + begin);
  });
  check_finite(path, type, out);
}

SampleStream::SampleStream(std::string path, size_t count, SampleType type, bool big_endian,
                           std::vector<float>& out)
    : path_(std::move(path)), count_(count), type_(type), big_endian_(big_endian), out_(out) {
  // Room for every sample, but filled only as the bytes come: a header that announces more
  // than its data holds costs no more memory than the data.
  out_.clear();
  try {
    out_.reserve(count);
  } catch (const std::bad_alloc&) {
    throw InputError(path_, "the header announces " + format_count(static_cast<long long>(count)) +
                                " samples, more than this computer's memory holds as floats");
  }
}

void SampleStream::add(const char* data, size_t n) {
  const size_t size = sample_size(type_);
  received_ += n;
  if (partial_ > 0) {  // the rest of a sample the last piece began
    const size_t take = std::min(n, size - partial_);
    std::memcpy(carry_ + partial_, data, take);
    partial_ += take;
    data += take;
    n -= take;
    if (partial_ < size) return;
    if (done_ < count_) {
      out_.resize(done_ + 1);
      convert_range(type_, big_endian_, carry_, 1, out_.data() + done_++);
    }
    partial_ = 0;
  }
  const size_t whole = n / size, usable = std::min(whole, count_ - done_);
  out_.resize(done_ + usable);
  convert_range(type_, big_endian_, data, usable, out_.data() + done_);
  done_ += usable;
  partial_ = n - whole * size;
  std::memcpy(carry_, data + whole * size, partial_);
}

void SampleStream::finish() {
  const size_t need = count_ * sample_size(type_);
  if (received_ < need) too_few_bytes(path_, count_, need, received_);
  check_finite(path_, type_, out_);
}

void flip_axes(Volume& v, const Eigen::Vector3d& signs) {
  const Eigen::Matrix3d f = signs.asDiagonal();
  v.directions = f * v.directions;
  v.origin = f * v.origin;
}

void classify_kind(Volume& v) {
  for (float x : v.data)
    if (x != 0.0f && x != 1.0f) {
      v.kind = VolumeKind::CT;
      return;
    }
  v.kind = VolumeKind::Mask;
}

}  // namespace detail

namespace {
// A missing path without an extension was meant as a DICOM folder, most likely.
std::string ext_of_missing(const std::string& path) {
  return detail::lower_extension(path).empty() ? "no such file or folder" : "file not found";
}
}  // namespace

bool is_volume_path(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return true;
  const std::string ext = detail::lower_extension(path);
  return ext == ".inv3" || ext == ".nrrd" || ext == ".nhdr" || ext == ".nii" || ext == ".nii.gz" ||
         ext == ".dcm";
}

Volume read_volume(const std::string& path, const ReadVolumeParams& params) {
  std::error_code ec;
  const bool folder = std::filesystem::is_directory(path, ec);
  if (!std::filesystem::exists(path, ec)) throw InputError(path, ext_of_missing(path));
  Volume v;
  const std::string ext = detail::lower_extension(path);
  if (folder)
    v = detail::read_dicom_folder(path, params.dicom_series);
  else if (ext == ".inv3")
    v = detail::read_inv3(path);
  else if (ext == ".nrrd" || ext == ".nhdr")
    v = detail::read_nrrd(path, params.patient_frame);
  else if (ext == ".nii" || ext == ".nii.gz")
    v = detail::read_nifti(path, params.patient_frame);
  else
    throw InputError(path, "unknown volume format '" + ext +
                               "' (expected .inv3, .nrrd, .nhdr, .nii, .nii.gz or a DICOM folder)");
  for (int a = 0; a < 3; ++a)
    if (v.dims[a] < 2) throw InputError(path, "volume needs at least 2 samples along each axis");
  if (std::abs(v.directions.determinant()) < 1e-12)
    throw InputError(path, "the voxel axes are degenerate (zero volume per voxel)");
  return v;
}

}  // namespace cranioplan
