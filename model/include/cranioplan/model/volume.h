#pragma once
// A scalar volume (CT in Hounsfield units, or a label mask) on a possibly oblique grid, in the
// patient's frame: LPS (x to the patient's left, y to the back, z to the head), millimetres.
#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

namespace cranioplan {

enum class VolumeKind { CT, Mask };

struct Volume {
  std::array<int, 3> dims{0, 0, 0};  ///< number of samples along i, j, k (i fastest in `data`)
  std::vector<float> data;           ///< dims[0]*dims[1]*dims[2] samples, i fastest
  /// Columns are the world displacement (mm) of one step along i, j and k. May be oblique and
  /// need not be orthogonal; its determinant's sign tells the grid's handedness.
  Eigen::Matrix3d directions = Eigen::Matrix3d::Identity();
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  ///< world position of sample (0,0,0), mm
  VolumeKind kind = VolumeKind::CT;
  std::string description;  ///< e.g. "InVesalius project 'ProMED CT 0051'"
  /// The frame the file declared its positions in and how they were brought to the patient's
  /// LPS frame, e.g. "NIfTI sform (RAS), turned to LPS".
  std::string frame;
  /// What the reader did that a person should know (a series chosen among several, a
  /// resampling, a frame the file did not declare), one sentence each, naming the file.
  std::vector<std::string> warnings;

  size_t size() const { return static_cast<size_t>(dims[0]) * dims[1] * dims[2]; }
  size_t index(int i, int j, int k) const {
    return (static_cast<size_t>(k) * dims[1] + j) * dims[0] + i;
  }
  float at(int i, int j, int k) const { return data[index(i, j, k)]; }
  Eigen::Vector3d world(const Eigen::Vector3d& ijk) const { return origin + directions * ijk; }
  /// Spacing along each axis (mm): the lengths of the direction columns.
  Eigen::Vector3d spacing() const { return directions.colwise().norm().transpose(); }
  /// The default bone threshold for this kind: 300 HU for CT, 0.5 for masks.
  double default_threshold() const { return kind == VolumeKind::CT ? 300.0 : 0.5; }
};

}  // namespace cranioplan
