#include "cranioplan/algorithms/geometry/thin_plate_spline.h"

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace cranioplan {
namespace {
inline double kernel(double r2) { return r2 > 0 ? 0.5 * r2 * std::log(r2) : 0.0; }  // r² log r
inline Eigen::Matrix<double, 6, 1> monomials(const Eigen::Vector2d& q) {
  Eigen::Matrix<double, 6, 1> m;
  m << 1.0, q.x(), q.y(), q.x() * q.x(), q.x() * q.y(), q.y() * q.y();
  return m;
}
}  // namespace

bool ThinPlateSpline::fit(const std::vector<Eigen::Vector2d>& sites,
                          const std::vector<double>& values, const std::vector<double>& smoothing,
                          double min_separation, size_t keep_first) {
  sites_.clear();
  std::vector<double> vals, lambdas;
  for (size_t i = 0; i < sites.size(); ++i) {
    bool duplicate = false;
    const double sep = i < keep_first ? 1e-6 : min_separation;
    for (const auto& s : sites_)
      if ((s - sites[i]).squaredNorm() < sep * sep) duplicate = true;
    if (duplicate) continue;
    sites_.push_back(sites[i]);
    vals.push_back(values[i]);
    lambdas.push_back(smoothing.empty() ? 0.0 : smoothing[i]);
  }
  const int n = static_cast<int>(sites_.size());
  if (n < 3) {
    sites_.clear();
    return false;
  }
  // Centre and scale the sites to about unit size for a well-conditioned system.
  shift_.setZero();
  for (const auto& s : sites_) shift_ += s;
  shift_ /= n;
  scale_ = 0.0;
  for (const auto& s : sites_) scale_ = std::max(scale_, (s - shift_).norm());
  if (scale_ <= 0) scale_ = 1.0;
  for (auto& s : sites_) s = (s - shift_) / scale_;
  // Sites on a line leave the surface across it undetermined (the system is singular, and
  // heights that happen to be consistent along the line would still solve it).
  Eigen::Matrix2d spread = Eigen::Matrix2d::Zero();
  for (const auto& s : sites_) spread += s * s.transpose();
  if (Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(spread).eigenvalues()[0] < 1e-10 * n) {
    sites_.clear();
    return false;
  }

  // Quadratic trend by least squares (needs 6 sites not on a conic; otherwise none).
  trend_.setZero();
  if (quadratic_trend_ && n >= 12) {
    Eigen::MatrixXd M(n, 6);
    Eigen::VectorXd y(n);
    for (int i = 0; i < n; ++i) {
      M.row(i) = monomials(sites_[i]).transpose();
      y[i] = vals[i];
    }
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(M);
    if (qr.rank() == 6) trend_ = qr.solve(y);
  }
  for (int i = 0; i < n; ++i) vals[i] -= trend_.dot(monomials(sites_[i]));

  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n + 3, n + 3);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(n + 3);
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j)
      A(i, j) = A(j, i) = kernel((sites_[i] - sites_[j]).squaredNorm());
    A(i, i) = lambdas[i];
    A(i, n) = A(n, i) = 1.0;
    A(i, n + 1) = A(n + 1, i) = sites_[i].x();
    A(i, n + 2) = A(n + 2, i) = sites_[i].y();
    b[i] = vals[i];
  }
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(A);
  const Eigen::VectorXd x = lu.solve(b);
  if (!x.allFinite() || (A * x - b).norm() > 1e-6 * (1.0 + b.norm())) {
    sites_.clear();
    return false;
  }
  weights_ = x.head(n);
  affine_ = x.tail<3>();
  return true;
}

double ThinPlateSpline::operator()(const Eigen::Vector2d& p) const {
  const Eigen::Vector2d q = (p - shift_) / scale_;
  double h = trend_.dot(monomials(q)) + affine_[0] + affine_[1] * q.x() + affine_[2] * q.y();
  for (size_t i = 0; i < sites_.size(); ++i)
    h += weights_[static_cast<int>(i)] * kernel((q - sites_[i]).squaredNorm());
  return h;
}

Eigen::Vector2d ThinPlateSpline::gradient(const Eigen::Vector2d& p) const {
  const Eigen::Vector2d q = (p - shift_) / scale_;
  Eigen::Vector2d g(affine_[1] + trend_[1] + 2 * trend_[3] * q.x() + trend_[4] * q.y(),
                    affine_[2] + trend_[2] + trend_[4] * q.x() + 2 * trend_[5] * q.y());
  for (size_t i = 0; i < sites_.size(); ++i) {
    const Eigen::Vector2d d = q - sites_[i];
    const double r2 = d.squaredNorm();
    if (r2 > 0) g += weights_[static_cast<int>(i)] * d * (std::log(r2) + 1.0);  // ∇(r² log r)
  }
  return g / scale_;
}

}  // namespace cranioplan
