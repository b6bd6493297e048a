#pragma once
// Private: one reader per volume format, and the sample conversion they share.
#include <string>

#include "cranioplan/algorithms/io/read_volume.h"
#include "cranioplan/model/volume.h"
#include "file_bytes.h"

namespace cranioplan::detail {

/// Converts `count` raw samples into floats. Throws InputError when fewer bytes are available.
void convert_samples(const std::string& path, const char* data, size_t available, size_t count,
                     SampleType type, bool big_endian, std::vector<float>& out);

/// The same for samples whose bytes come in pieces (a stream being decompressed): each piece's
/// whole samples are converted as it comes, a sample split between two pieces when its rest
/// comes. Bytes beyond the samples are ignored.
class SampleStream {
 public:
  SampleStream(std::string path, size_t count, SampleType type, bool big_endian,
               std::vector<float>& out);
  void add(const char* data, size_t n);
  /// Throws InputError, as convert_samples does, when fewer bytes came than the samples need.
  void finish();

 private:
  std::string path_;
  size_t count_;
  SampleType type_;
  bool big_endian_;
  std::vector<float>& out_;
  size_t received_ = 0, done_ = 0, partial_ = 0;
  char carry_[8] = {};
};

/// Marks the volume as a mask when all samples are 0 or 1.
void classify_kind(Volume& v);

/// Turns positions written in a space whose axes are LPS's times `signs` (RAS: -1, -1, 1) into
/// LPS.
void flip_axes(Volume& v, const Eigen::Vector3d& signs);

Volume read_inv3(const std::string& path);
Volume read_nrrd(const std::string& path, bool patient_frame);
Volume read_nifti(const std::string& path, bool patient_frame);
/// Reads a DICOM series in a child process (isolated_read.h): a file the DICOM library dies on is
/// an InputError naming it.
Volume read_dicom_folder(const std::string& path, const std::string& series_uid);
/// The series of a DICOM folder, scanned in a child process as read_dicom_folder reads.
std::vector<DicomSeries> dicom_series_of(const std::string& folder);

}  // namespace cranioplan::detail
