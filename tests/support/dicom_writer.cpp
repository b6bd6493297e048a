#include "support/dicom_writer.h"

#include <gdcmAttribute.h>
#include <gdcmImageChangeTransferSyntax.h>
#include <gdcmImageWriter.h>
#include <gdcmTrace.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <numeric>
#include <random>
#include <stdexcept>
#include <vector>

namespace cranioplan::test {
namespace {

// A text element (UI, CS, LO, PN, IS, DS), padded to even length as DICOM wants.
template <uint16_t G, uint16_t E>
void put(gdcm::DataSet& ds, std::string value) {
  const gdcm::Tag tag(G, E);
  const gdcm::VR vr = gdcm::Attribute<G, E>::GetVR();
  if (value.size() % 2) value.push_back(vr == gdcm::VR::UI ? '\0' : ' ');
  gdcm::DataElement e(tag);
  e.SetVR(vr);
  e.SetByteValue(value.data(), static_cast<uint32_t>(value.size()));
  ds.Replace(e);
}

gdcm::TransferSyntax::TSType syntax(DicomSeriesOptions::Compression c) {
  switch (c) {
    case DicomSeriesOptions::Compression::RLE:
      return gdcm::TransferSyntax::RLELossless;
    case DicomSeriesOptions::Compression::JPEGLossless:
      return gdcm::TransferSyntax::JPEGLosslessProcess14_1;
    case DicomSeriesOptions::Compression::JPEGLS:
      return gdcm::TransferSyntax::JPEGLSLossless;
    case DicomSeriesOptions::Compression::None:
      break;
  }
  return gdcm::TransferSyntax::ExplicitVRLittleEndian;
}

}  // namespace

void write_dicom_series(const Volume& v, const std::string& folder,
                        const DicomSeriesOptions& options) {
  std::filesystem::create_directories(folder);
  gdcm::Trace::WarningOff();  // "No PhotometricInterpretation found" before it is written
  const Eigen::Vector3d sp = v.spacing();
  const Eigen::Vector3d row_dir = v.directions.col(0) / sp[0];
  const Eigen::Vector3d col_dir = v.directions.col(1) / sp[1];
  if (std::abs(row_dir.dot(col_dir)) > 1e-6)
    throw std::invalid_argument("write_dicom_series: the slice axes must be perpendicular");
  // File number of each slice.
  std::vector<int> number(static_cast<size_t>(v.dims[2]));
  std::iota(number.begin(), number.end(), 1);
  if (options.order == DicomSeriesOptions::Order::Reverse)
    std::reverse(number.begin(), number.end());
  if (options.order == DicomSeriesOptions::Order::Shuffled)
    std::shuffle(number.begin(), number.end(), std::mt19937(7));
  for (int k = 0; k < v.dims[2]; ++k) {
    if (options.skip.count(k)) continue;
    gdcm::ImageWriter writer;
    gdcm::Image& image = writer.GetImage();
    image.SetNumberOfDimensions(2);
    image.SetDimension(0, static_cast<unsigned>(v.dims[0]));
    image.SetDimension(1, static_cast<unsigned>(v.dims[1]));
    image.SetPixelFormat(gdcm::PixelFormat::INT16);
    image.SetPhotometricInterpretation(gdcm::PhotometricInterpretation::MONOCHROME2);
    image.SetTransferSyntax(gdcm::TransferSyntax::ExplicitVRLittleEndian);
    const Eigen::Vector3d ipp = v.world(Eigen::Vector3d(0, 0, k));
    const double origin[3] = {ipp.x(), ipp.y(), ipp.z()};
    const double cosines[6] = {row_dir.x(), row_dir.y(), row_dir.z(),
                               col_dir.x(), col_dir.y(), col_dir.z()};
    // SetOrigin(const double*) takes only as many values as the image has dimensions (2).
    for (unsigned a = 0; a < 3; ++a) image.SetOrigin(a, origin[a]);
    image.SetDirectionCosines(cosines);
    image.SetSpacing(0, sp[0]);  // between columns
    image.SetSpacing(1, sp[1]);  // between rows
    image.SetSpacing(2, sp[2]);
    image.SetSlope(options.slope);
    image.SetIntercept(options.intercept);
    std::vector<int16_t> pixels(static_cast<size_t>(v.dims[0]) * v.dims[1]);
    for (int j = 0; j < v.dims[1]; ++j)
      for (int i = 0; i < v.dims[0]; ++i)
        pixels[static_cast<size_t>(j) * v.dims[0] + i] =
            static_cast<int16_t>(std::lround((v.at(i, j, k) - options.intercept) / options.slope));
    gdcm::DataElement pixel_data(gdcm::Tag(0x7fe0, 0x0010));
    pixel_data.SetByteValue(reinterpret_cast<const char*>(pixels.data()),
                            static_cast<uint32_t>(pixels.size() * sizeof(int16_t)));
    image.SetDataElement(pixel_data);

    gdcm::DataSet& ds = writer.GetFile().GetDataSet();
    put<0x0008, 0x0016>(ds, "1.2.840.10008.5.1.4.1.1.2");  // CT Image Storage
    put<0x0008, 0x0018>(ds, options.series_uid + "." + std::to_string(number[k]));
    // One study date and time for the whole series (GDCM's writer would stamp each file with
    // its own moment, and converters such as dcm2niix then split the series).
    put<0x0008, 0x0020>(ds, "20260101");
    put<0x0008, 0x0030>(ds, "120000");
    put<0x0008, 0x0021>(ds, "20260101");
    put<0x0008, 0x0031>(ds, "120000");
    put<0x0008, 0x0060>(ds, options.modality);
    put<0x0008, 0x0070>(ds, "Cranioplan tests");
    put<0x0008, 0x103e>(ds, options.description);
    put<0x0010, 0x0010>(ds, "Phantom^Asymmetric");
    put<0x0020, 0x000d>(ds, "1.2.826.0.1.3680043.9.7163.1");
    put<0x0020, 0x000e>(ds, options.series_uid);
    put<0x0020, 0x0013>(ds, std::to_string(number[k]));
    put<0x0018, 0x0050>(ds, std::to_string(sp[2]));

    if (options.compression != DicomSeriesOptions::Compression::None) {
      gdcm::ImageChangeTransferSyntax change;
      change.SetTransferSyntax(syntax(options.compression));
      change.SetInput(image);
      if (!change.Change()) throw std::runtime_error("GDCM could not compress a slice");
      writer.SetImage(change.GetOutput());
    }
    char name[64];
    std::snprintf(name, sizeof(name), "/%s%04d.dcm", options.file_prefix.c_str(), number[k]);
    writer.SetFileName((folder + name).c_str());
    if (!writer.Write()) throw std::runtime_error(std::string("GDCM could not write ") + name);
  }
}

}  // namespace cranioplan::test
