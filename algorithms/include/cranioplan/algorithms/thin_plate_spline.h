#pragma once
// A thin-plate spline height field h(u, v) over scattered sites, interpolating (or, with a
// per-site smoothing weight, approximating) the given heights.
#include <Eigen/Core>
#include <vector>

namespace cranioplan {

class ThinPlateSpline {
 public:
  /// Fits through `sites` (2D, mm) with `values` (mm). `smoothing` is empty (interpolate) or
  /// one non-negative weight per site (0 = pass through it). Sites closer than 1 µm to an earlier
  /// one are dropped. Returns false when the sites are fewer than 3 or collinear.
  bool fit(const std::vector<Eigen::Vector2d>& sites, const std::vector<double>& values,
           const std::vector<double>& smoothing = {});
  double operator()(const Eigen::Vector2d& p) const;
  /// ∂h/∂u, ∂h/∂v at p.
  Eigen::Vector2d gradient(const Eigen::Vector2d& p) const;
  bool valid() const { return !sites_.empty(); }

 private:
  std::vector<Eigen::Vector2d> sites_;  // scaled by 1/scale_
  Eigen::VectorXd weights_;
  Eigen::Vector3d affine_ = Eigen::Vector3d::Zero();
  Eigen::Vector2d shift_ = Eigen::Vector2d::Zero();
  double scale_ = 1.0;
};

}  // namespace cranioplan
