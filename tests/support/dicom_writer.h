#pragma once
// DICOM series written through GDCM's writer, so tests can build series whose geometry is
// known: any orientation, slices stored in any order, compressed transfer syntaxes.
#include <set>
#include <string>

#include "cranioplan/model/volume.h"

namespace cranioplan::test {

struct DicomSeriesOptions {
  enum class Order { Forward, Reverse, Shuffled };
  /// Forward: file names and InstanceNumbers follow k. Reverse: the last slice is file 1.
  /// Shuffled: names and InstanceNumbers in an order unrelated to position.
  Order order = Order::Forward;
  enum class Compression { None, RLE, JPEGLossless, JPEGLS };
  Compression compression = Compression::None;
  std::string series_uid = "1.2.826.0.1.3680043.9.7163.1.1";
  std::string description = "phantom";
  std::string modality = "CT";
  std::string file_prefix = "slice";
  std::set<int> skip;  ///< slices (k) not written, for series with a gap
  double slope = 1.0, intercept = -1024.0;
};

/// Writes one file per k-slice of `v` into `folder` (created if absent): columns along i,
/// rows along j, ImageOrientationPatient from the first two direction columns (which must be
/// perpendicular), ImagePositionPatient = v.world(0, 0, k), PixelSpacing from their lengths,
/// stored values (HU − intercept) / slope as 16-bit signed integers.
void write_dicom_series(const Volume& v, const std::string& folder,
                        const DicomSeriesOptions& options = {});

}  // namespace cranioplan::test
