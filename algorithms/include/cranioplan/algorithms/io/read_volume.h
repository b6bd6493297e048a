#pragma once
// Reading CT and label volumes: InVesalius projects (.inv3), NRRD (.nrrd/.nhdr, raw or gzip),
// NIfTI-1 (.nii/.nii.gz) and DICOM series (a folder of slices).
#include <string>
#include <vector>

#include "cranioplan/model/volume.h"

namespace cranioplan {

struct ReadVolumeParams {
  /// A DICOM folder's series to read (its SeriesInstanceUID); empty: the largest CT series
  /// (Volume::warnings says which was read when the folder holds several).
  std::string dicom_series;
  /// Positions in the patient's LPS frame (true), whatever space the file declares (NIfTI's
  /// RAS, a NRRD `space` of right-anterior-superior, ...). false: a NRRD's or NIfTI's
  /// positions as the file writes them, as plans saved before the patient frame were read.
  bool patient_frame = true;
};

/// Reads a volume in the patient's frame (LPS, mm): NRRD `space directions`/`space origin`
/// (also oblique) in the `space` the header names, NIfTI sform (else qform) turned from RAS,
/// DICOM ImagePositionPatient/ImageOrientationPatient with slices ordered along the normal
/// (GDCM), InVesalius projects after InVesalius's own layout (docs/FRAMES.md). Volume::frame
/// says what the file declared. Volumes of integer type with only the values 0 and 1 (or a
/// NRRD/NIfTI label volume) are masks; everything else is CT. Throws InputError naming the
/// file and the problem, including a header that disagrees with the data.
Volume read_volume(const std::string& path, const ReadVolumeParams& params = {});

/// One series (or one stack of a series: slices that share size and orientation) of a DICOM
/// folder.
struct DicomSeries {
  std::string uid;          ///< SeriesInstanceUID
  std::string description;  ///< SeriesDescription
  std::string modality;     ///< "CT", "MR", ...
  int rows = 0, columns = 0;
  long long slices = 0;
};

/// The series of a DICOM folder (searched to a depth of 8), in the order their first file
/// sorts. Throws InputError when the folder does not exist or holds no files.
std::vector<DicomSeries> list_dicom_series(const std::string& folder);

/// True when the path names something read_volume understands (by extension, or a folder).
bool is_volume_path(const std::string& path);

}  // namespace cranioplan
