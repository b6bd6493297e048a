#pragma once
// A thin-plate spline height field h(u, v) over scattered sites, interpolating (or, with a
// per-site smoothing weight, approximating) the given heights. A quadratic trend is fitted
// first by least squares and the spline interpolates what it leaves: across a hole with data
// only around it, the surface then keeps the curvature of its surroundings instead of
// flattening (or buckling) as a plain spline does.
#include <Eigen/Core>
#include <vector>

namespace cranioplan {

class ThinPlateSpline {
 public:
  /// Fits through `sites` (2D, mm) with `values` (mm). `smoothing` is empty (interpolate) or
  /// one non-negative weight per site (0 = pass through it). A site closer than
  /// `min_separation` to an earlier one is dropped (earlier sites win: pass the ones that must
  /// be met first), since two nearby sites with different heights make the spline oscillate.
  /// The first `keep_first` sites are only dropped when they coincide (1 µm).
  /// Returns false when the sites are fewer than 3 or collinear.
  bool fit(const std::vector<Eigen::Vector2d>& sites, const std::vector<double>& values,
           const std::vector<double>& smoothing = {}, double min_separation = 1e-6,
           size_t keep_first = 0);
  double operator()(const Eigen::Vector2d& p) const;
  /// ∂h/∂u, ∂h/∂v at p.
  Eigen::Vector2d gradient(const Eigen::Vector2d& p) const;
  bool valid() const { return !sites_.empty(); }
  /// Whether fit() removes a quadratic trend first (default true). Fields that vary little,
  /// such as a thickness, extrapolate more calmly with the affine part alone.
  void set_quadratic_trend(bool on) { quadratic_trend_ = on; }

 private:
  std::vector<Eigen::Vector2d> sites_;  // scaled by 1/scale_
  Eigen::VectorXd weights_;
  Eigen::Vector3d affine_ = Eigen::Vector3d::Zero();
  Eigen::Vector2d shift_ = Eigen::Vector2d::Zero();
  Eigen::Matrix<double, 6, 1> trend_ = Eigen::Matrix<double, 6, 1>::Zero();  // 1 u v u² uv v²
  double scale_ = 1.0;
  bool quadratic_trend_ = true;
};

}  // namespace cranioplan
