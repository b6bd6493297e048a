#pragma once
// A minimal DICOM writer (explicit VR little endian, 16-bit CT slices) so tests can build a
// series whose geometry is known.
#include <string>

#include "cranioplan/model/volume.h"

namespace cranioplan::test {

/// Writes one file per k-slice of `v` into `folder` (which must exist). The grid must be axial
/// and axis-aligned with positive spacing; rows run along +y (DICOM's column direction).
/// Sample values are stored as HU + 1024 with rescale intercept −1024.
void write_dicom_series(const Volume& v, const std::string& folder);

}  // namespace cranioplan::test
