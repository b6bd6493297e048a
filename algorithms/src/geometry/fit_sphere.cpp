#include "cranioplan/algorithms/geometry/fit_sphere.h"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>

namespace cranioplan {

std::optional<FittedSphere> fit_sphere(const std::vector<Eigen::Vector3d>& points,
                                       const std::vector<size_t>& idx) {
  if (idx.size() < 4) return std::nullopt;
  Eigen::MatrixXd A(idx.size(), 4);
  Eigen::VectorXd b(idx.size());
  for (size_t k = 0; k < idx.size(); ++k) {
    const Eigen::Vector3d& p = points[idx[k]];
    A.row(static_cast<Eigen::Index>(k)) << 2.0 * p.x(), 2.0 * p.y(), 2.0 * p.z(), 1.0;
    b[static_cast<Eigen::Index>(k)] = p.squaredNorm();
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
  if (qr.rank() < 4) return std::nullopt;
  const Eigen::Vector4d x = qr.solve(b);
  const FittedSphere sphere{x.head<3>(),
                            std::sqrt(std::max(0.0, x[3] + x.head<3>().squaredNorm()))};
  if (!sphere.center.allFinite() || !std::isfinite(sphere.radius)) return std::nullopt;
  return sphere;
}

}  // namespace cranioplan
