#pragma once
// Reading CT and label volumes: InVesalius projects (.inv3), NRRD (.nrrd/.nhdr, raw or gzip),
// NIfTI-1 (.nii/.nii.gz) and DICOM series (a folder of slices).
#include <string>

#include "cranioplan/model/volume.h"

namespace cranioplan {

/// Reads a volume in its own world coordinates (mm): NRRD `space directions`/`space origin`
/// (also oblique), NIfTI sform (else qform), DICOM ImagePositionPatient/ImageOrientationPatient.
/// Volumes of integer type with only the values 0 and 1 (or a NRRD/NIfTI label volume) are
/// masks; everything else is CT. Throws InputError naming the file and the problem, including
/// a header that disagrees with the data.
Volume read_volume(const std::string& path);

/// True when the path names something read_volume understands (by extension, or a folder).
bool is_volume_path(const std::string& path);

}  // namespace cranioplan
