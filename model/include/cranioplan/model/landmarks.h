#pragma once
#include <Eigen/Core>
#include <optional>
#include <vector>

namespace cranioplan {

/// Named anatomical landmarks for the midsagittal plane, in mm (skull coordinates).
/// nasion and the two orbit centres are the required minimum; midline points are optional
/// extra points on the midsagittal plane (e.g. opisthocranion, vertex, foramen magnum).
struct Landmarks {
  std::optional<Eigen::Vector3d> nasion;
  std::optional<Eigen::Vector3d> orbit_left;
  std::optional<Eigen::Vector3d> orbit_right;
  std::vector<Eigen::Vector3d> midline;

  bool has_required() const { return nasion && orbit_left && orbit_right; }
  bool empty() const { return !nasion && !orbit_left && !orbit_right && midline.empty(); }
};

}  // namespace cranioplan
