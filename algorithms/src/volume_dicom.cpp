// DICOM series: every slice file of one folder, read by VTK's DICOM reader. World coordinates
// follow ImagePositionPatient and ImageOrientationPatient (LPS, mm); values in Hounsfield units
// (VTK's reader applies the rescale slope and intercept).
#include <vtkDICOMImageReader.h>
#include <vtkDataArray.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPointData.h>

#include <Eigen/Geometry>
#include <filesystem>

#include "cranioplan/model/error.h"
#include "volume_formats.h"
#include "vtk_errors.h"

namespace cranioplan::detail {

Volume read_dicom_folder(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  bool any_file = false;
  for (const auto& entry : fs::directory_iterator(path, ec))
    if (entry.is_regular_file()) any_file = true;
  if (!any_file) throw InputError(path, "folder holds no files (expected a DICOM series)");

  vtkNew<vtkDICOMImageReader> reader;
  const VtkErrorCatcher errors(reader);
  reader->SetDirectoryName(path.c_str());
  reader->Update();
  const std::string error = errors.message(160);
  vtkImageData* img = reader->GetOutput();
  int dims[3] = {0, 0, 0};
  if (img) img->GetDimensions(dims);
  if (!error.empty() || !img || !img->GetPointData()->GetScalars() || dims[2] < 2)
    throw InputError(path, "not a readable DICOM series of two or more slices" +
                               (error.empty() ? std::string() : " (" + error + ")"));
  Volume v;
  v.dims = {dims[0], dims[1], dims[2]};
  double spacing[3];
  img->GetSpacing(spacing);
  const float* iop = reader->GetImageOrientationPatient();
  Eigen::Vector3d row_dir(1, 0, 0), col_dir(0, 1, 0);
  if (iop) {
    row_dir = Eigen::Vector3d(iop[0], iop[1], iop[2]);
    col_dir = Eigen::Vector3d(iop[3], iop[4], iop[5]);
    if (row_dir.norm() < 0.5 || col_dir.norm() < 0.5) {
      row_dir = Eigen::Vector3d::UnitX();
      col_dir = Eigen::Vector3d::UnitY();
    }
  }
  row_dir.normalize();
  col_dir.normalize();
  const Eigen::Vector3d slice_dir = row_dir.cross(col_dir);
  const float* ipp = reader->GetImagePositionPatient();
  const Eigen::Vector3d first(ipp[0], ipp[1], ipp[2]);
  // VTK's reader stores rows bottom-up: VTK row j is DICOM row (rows - 1 - j).
  v.directions.col(0) = row_dir * spacing[0];
  v.directions.col(1) = -col_dir * spacing[1];
  v.directions.col(2) = slice_dir * spacing[2];
  v.origin = first + col_dir * spacing[1] * (dims[1] - 1);
  vtkDataArray* s = img->GetPointData()->GetScalars();
  v.data.resize(v.size());
  if (static_cast<size_t>(s->GetNumberOfTuples()) < v.size())
    throw InputError(path, "DICOM series holds fewer samples than its slices announce");
  for (size_t i = 0; i < v.size(); ++i)
    v.data[i] = static_cast<float>(
        s->GetComponent(static_cast<vtkIdType>(i), 0));  // VTK applied the rescale
  v.description = "DICOM series " + std::to_string(dims[0]) + "×" + std::to_string(dims[1]) + "×" +
                  std::to_string(dims[2]);
  v.kind = VolumeKind::CT;
  return v;
}

}  // namespace cranioplan::detail
