#pragma once
#include <Eigen/Core>

namespace cranioplan {

/// A rigid transform x ↦ R·x + t (R a rotation, t in mm).
struct RigidTransform {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Eigen::Vector3d apply(const Eigen::Vector3d& x) const { return rotation * x + translation; }
  /// Normals and other directions: rotation only.
  Eigen::Vector3d apply_direction(const Eigen::Vector3d& v) const { return rotation * v; }
  RigidTransform inverse() const;
  /// (this ∘ other)(x) = this(other(x)).
  RigidTransform operator*(const RigidTransform& other) const;

  /// Rotation angle in degrees (0..180).
  double rotation_angle_deg() const;

  /// From an axis (not necessarily unit), an angle in degrees and a translation.
  static RigidTransform from_axis_angle(const Eigen::Vector3d& axis, double angle_deg,
                                        const Eigen::Vector3d& translation);
};

}  // namespace cranioplan
