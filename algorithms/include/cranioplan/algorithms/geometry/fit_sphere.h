#pragma once

// A sphere fitted to points by least squares.

#include <Eigen/Core>
#include <optional>
#include <vector>

namespace cranioplan {

struct FittedSphere {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double radius = 0.0;
};

/// The least-squares sphere through points[idx] (the algebraic fit |p|² = 2 c·p + k, solved by
/// column-pivoting QR); none when fewer than four points or they lie in a plane, or the result
/// is not finite.
std::optional<FittedSphere> fit_sphere(const std::vector<Eigen::Vector3d>& points,
                                       const std::vector<size_t>& idx);

}  // namespace cranioplan
