#include "cranioplan/model/rigid_transform.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace cranioplan {

RigidTransform RigidTransform::inverse() const {
  RigidTransform inv;
  inv.rotation = rotation.transpose();
  inv.translation = -(inv.rotation * translation);
  return inv;
}

RigidTransform RigidTransform::operator*(const RigidTransform& other) const {
  RigidTransform out;
  out.rotation = rotation * other.rotation;
  out.translation = rotation * other.translation + translation;
  return out;
}

double RigidTransform::rotation_angle_deg() const {
  const double c = std::clamp((rotation.trace() - 1.0) / 2.0, -1.0, 1.0);
  return std::acos(c) * 180.0 / M_PI;
}

RigidTransform RigidTransform::from_axis_angle(const Eigen::Vector3d& axis, double angle_deg,
                                               const Eigen::Vector3d& translation) {
  RigidTransform t;
  t.rotation = Eigen::AngleAxisd(angle_deg * M_PI / 180.0, axis.normalized()).toRotationMatrix();
  t.translation = translation;
  return t;
}

}  // namespace cranioplan
