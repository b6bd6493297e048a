#pragma once
#include <Eigen/Core>

namespace cranioplan {

/// An oriented plane n·x = d with unit normal n and offset d (mm).
/// For a midsagittal plane the normal points from the patient's left to right by convention
/// of the caller; reflection does not depend on the sign.
struct Plane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();
  double offset = 0.0;  ///< d in n·x = d, mm

  /// Plane through `point` with the given (not necessarily unit) normal.
  static Plane through(const Eigen::Vector3d& point, const Eigen::Vector3d& normal);

  double signed_distance(const Eigen::Vector3d& x) const { return normal.dot(x) - offset; }
  Eigen::Vector3d project(const Eigen::Vector3d& x) const {
    return x - signed_distance(x) * normal;
  }
  Eigen::Vector3d reflect(const Eigen::Vector3d& x) const {
    return x - 2.0 * signed_distance(x) * normal;
  }
  /// The same plane with the normal (and offset) negated.
  Plane flipped() const { return {-normal, -offset}; }

  /// Angle between the planes' normals, ignoring orientation, in degrees (0..90).
  double angle_to_deg(const Plane& other) const;
};

/// The unit direction of `v` across the unit `axis` (its projection onto the plane through the
/// origin normal to the axis), or any unit vector across the axis when `v` lies along it.
Eigen::Vector3d unit_across(const Eigen::Vector3d& v, const Eigen::Vector3d& axis);

}  // namespace cranioplan
