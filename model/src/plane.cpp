#include "cranioplan/model/plane.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cassert>
#include <cmath>

namespace cranioplan {

Plane Plane::through(const Eigen::Vector3d& point, const Eigen::Vector3d& normal) {
  assert(normal.norm() > 0.0 && "plane normal must not be zero");
  Plane p;
  p.normal = normal.normalized();
  p.offset = p.normal.dot(point);
  return p;
}

double Plane::angle_to_deg(const Plane& other) const {
  const double c = std::min(1.0, std::abs(normal.normalized().dot(other.normal.normalized())));
  return std::acos(c) * 180.0 / M_PI;
}

Eigen::Vector3d unit_across(const Eigen::Vector3d& v, const Eigen::Vector3d& axis) {
  const Eigen::Vector3d across = v - v.dot(axis) * axis;
  return across.norm() > 1e-9 ? Eigen::Vector3d(across.normalized()) : axis.unitOrthogonal();
}

}  // namespace cranioplan
