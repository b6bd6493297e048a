// NIfTI-1 volumes (.nii, .nii.gz): world coordinates from the sform when set, else the qform,
// else the voxel sizes; NIfTI's RAS turned to the patient's LPS. Both byte orders.
#include <cmath>
#include <cstdint>
#include <cstring>

#include "cranioplan/algorithms/io/file_io.h"
#include "cranioplan/model/error.h"
#include "file_bytes.h"
#include "volume_formats.h"

namespace cranioplan::detail {
namespace {

struct HeaderReader {
  const std::string& bytes;
  bool swap;
  template <class T>
  T get(size_t offset) const {
    unsigned char b[sizeof(T)];
    std::memcpy(b, bytes.data() + offset, sizeof(T));
    if (swap)
      for (size_t k = 0; k < sizeof(T) / 2; ++k) std::swap(b[k], b[sizeof(T) - 1 - k]);
    T v;
    std::memcpy(&v, b, sizeof(T));
    return v;
  }
};

}  // namespace

Volume read_nifti(const std::string& path, bool patient_frame) {
  const std::string raw = read_file_bytes(path);
  const bool gz = raw.size() >= 2 && static_cast<unsigned char>(raw[0]) == 0x1f &&
                  static_cast<unsigned char>(raw[1]) == 0x8b;
  const std::string bytes = gz ? gunzip(path, raw.data(), raw.size()) : raw;
  if (bytes.size() < 348) throw InputError(path, "too short for a NIfTI-1 header (348 bytes)");
  int32_t sizeof_hdr;
  std::memcpy(&sizeof_hdr, bytes.data(), 4);
  bool swap = false;
  if (sizeof_hdr != 348) {
    swap = true;
    if (HeaderReader{bytes, true}.get<int32_t>(0) != 348)
      throw InputError(path, "not a NIfTI-1 file (header size field is not 348)");
  }
  const HeaderReader h{bytes, swap};
  if (std::memcmp(bytes.data() + 344, "n+1", 4) != 0)
    throw InputError(path, "only single-file NIfTI-1 ('n+1') is supported");
  const int16_t ndim = h.get<int16_t>(40);
  if (ndim < 3 || ndim > 7) throw InputError(path, "NIfTI dim[0] must be 3 or more");
  Volume v;
  for (int a = 0; a < 3; ++a) {
    const int16_t d = h.get<int16_t>(42 + 2 * a);
    if (d < 1) throw InputError(path, "NIfTI dimensions must be positive");
    v.dims[a] = d;
  }
  for (int a = 3; a < ndim; ++a)
    if (h.get<int16_t>(42 + 2 * a) > 1)
      throw InputError(path, "4D and higher NIfTI volumes are not supported");
  SampleType type;
  switch (h.get<int16_t>(70)) {
    case 2:
      type = SampleType::UInt8;
      break;
    case 4:
      type = SampleType::Int16;
      break;
    case 8:
      type = SampleType::Int32;
      break;
    case 16:
      type = SampleType::Float32;
      break;
    case 64:
      type = SampleType::Float64;
      break;
    case 256:
      type = SampleType::Int8;
      break;
    case 512:
      type = SampleType::UInt16;
      break;
    case 768:
      type = SampleType::UInt32;
      break;
    default:
      throw InputError(
          path, "NIfTI datatype " + std::to_string(h.get<int16_t>(70)) + " is not supported");
  }
  float pixdim[8];
  for (int i = 0; i < 8; ++i) pixdim[i] = h.get<float>(76 + 4 * i);
  const float vox_offset = h.get<float>(108);
  if (!(vox_offset >= 348.0f) || vox_offset > static_cast<float>(bytes.size()))
    throw InputError(path, "NIfTI vox_offset points outside the file");
  const int16_t qform_code = h.get<int16_t>(252), sform_code = h.get<int16_t>(254);
  if (sform_code > 0) {
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) v.directions(r, c) = h.get<float>(280 + 16 * r + 4 * c);
      v.origin[r] = h.get<float>(280 + 16 * r + 12);
    }
  } else if (qform_code > 0) {
    const double b = h.get<float>(256), c = h.get<float>(260), d = h.get<float>(264);
    const double a = std::sqrt(std::max(0.0, 1.0 - b * b - c * c - d * d));
    Eigen::Matrix3d R;
    R << a * a + b * b - c * c - d * d, 2 * b * c - 2 * a * d, 2 * b * d + 2 * a * c,
        2 * b * c + 2 * a * d, a * a + c * c - b * b - d * d, 2 * c * d - 2 * a * b,
        2 * b * d - 2 * a * c, 2 * c * d + 2 * a * b, a * a + d * d - c * c - b * b;
    const double qfac = pixdim[0] < 0 ? -1.0 : 1.0;
    for (int col = 0; col < 3; ++col)
      v.directions.col(col) = R.col(col) * std::abs(pixdim[col + 1]) * (col == 2 ? qfac : 1.0);
    v.origin = {h.get<float>(268), h.get<float>(272), h.get<float>(276)};
  } else {
    for (int a = 0; a < 3; ++a)
      if (!(pixdim[a + 1] > 0)) throw InputError(path, "NIfTI voxel sizes must be positive");
    v.directions = Eigen::Vector3d(pixdim[1], pixdim[2], pixdim[3]).asDiagonal();
  }
  if (!v.directions.allFinite() || !v.origin.allFinite())
    throw InputError(path, "NIfTI orientation holds values that are not numbers");
  // NIfTI's sform and qform give RAS+ positions (x to the patient's right... negative: left).
  if (sform_code > 0 || qform_code > 0) {
    v.frame = std::string(sform_code > 0 ? "NIfTI sform" : "NIfTI qform") + " (RAS)";
    if (patient_frame) {
      flip_axes(v, Eigen::Vector3d(-1, -1, 1));
      v.frame += ", turned to LPS";
    }
  } else {
    v.frame = "none declared (NIfTI without sform or qform); the voxel axes read as LPS";
    v.warnings.push_back(path +
                         ": the file declares no orientation (neither sform nor qform), so "
                         "the patient's left and right are not known from it; its voxel axes "
                         "were read as left, posterior, superior");
  }
  const size_t offset = static_cast<size_t>(vox_offset);
  convert_samples(path, bytes.data() + offset, bytes.size() - offset, v.size(), type, swap, v.data);
  float slope = h.get<float>(112);
  const float inter = h.get<float>(116);
  if (slope != 0.0f && std::isfinite(slope) && std::isfinite(inter) &&
      (slope != 1.0f || inter != 0.0f))
    for (float& x : v.data) x = x * slope + inter;
  v.description = "NIfTI-1 " + std::to_string(v.dims[0]) + "×" + std::to_string(v.dims[1]) + "×" +
                  std::to_string(v.dims[2]);
  classify_kind(v);
  return v;
}

}  // namespace cranioplan::detail
