#include "cranioplan/algorithms/alignment/register_icp.h"

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>

#include "cranioplan/algorithms/alignment/mirror_mesh.h"
#include "cranioplan/algorithms/geometry/point_index.h"
#include "cranioplan/algorithms/geometry/surface_samples.h"
#include "cranioplan/model/parallel.h"

namespace cranioplan {

bool RegionOfInterest::contains(const Eigen::Vector3d& p) const {
  if (shape == Shape::Sphere) return (p - center).squaredNorm() <= radius * radius;
  return ((p - center).cwiseAbs().array() <= half_size.array()).all();
}

SkullMesh transform_mesh(const SkullMesh& mesh, const RigidTransform& transform) {
  SkullMesh out = mesh;
  for (auto vh : out.vertices())
    out.set_point(vh, to_point(transform.apply(to_eigen(out.point(vh)))));
  return out;
}

namespace {
struct Pair {
  Eigen::Vector3d p;  // moving sample, transformed
  Eigen::Vector3d q;  // fixed point
  Eigen::Vector3d n;  // fixed normal
  double r;           // signed point-to-plane residual
};

// The motion x = (rotation vector, translation) about `pivot`: p ↦ R·(p − pivot) + pivot + t.
RigidTransform small_motion(const Eigen::Matrix<double, 6, 1>& x, const Eigen::Vector3d& pivot) {
  const Eigen::Vector3d w = x.head<3>();
  const double angle = w.norm();
  RigidTransform t;
  if (angle > 0) t.rotation = Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
  t.translation = x.tail<3>() + pivot - t.rotation * pivot;
  return t;
}
}  // namespace

RegisterResult register_icp(const SkullMesh& moving, const SkullMesh& fixed,
                            const RegisterParams& params, const VertexCloud* fixed_cloud,
                            const VertexCloud* moving_cloud) {
  const auto t0 = std::chrono::steady_clock::now();
  RegisterResult result;
  result.transform = params.initial;
  if (moving.n_vertices() < 6 || fixed.n_vertices() < 6) {
    result.message = "both meshes need at least 6 vertices";
    return result;
  }
  std::unique_ptr<VertexCloud> own_fixed, own_moving;
  if (!fixed_cloud) fixed_cloud = (own_fixed = std::make_unique<VertexCloud>(fixed)).get();
  if (!moving_cloud)
    moving_cloud = &moving == &fixed ? fixed_cloud
                                     : (own_moving = std::make_unique<VertexCloud>(moving)).get();
  const SurfaceSamples& fixed_samples = fixed_cloud->samples;
  const PointIndex& index = fixed_cloud->index;
  const SurfaceSamples& moving_all = moving_cloud->samples;
  SurfaceSamples source;
  if (params.roi) {
    for (size_t i = 0; i < moving_all.points.size(); ++i)
      if (params.roi->contains(params.initial.apply(moving_all.points[i]))) {
        source.points.push_back(moving_all.points[i]);
        source.normals.push_back(moving_all.normals[i]);
      }
  } else {
    source = moving_all;
  }
  source = subsample(source, static_cast<size_t>(std::clamp(params.sample_count, 100, 200000)));
  if (source.points.size() < 6) {
    result.message = "fewer than 6 points of the moving mesh lie in the region of interest";
    return result;
  }

  RigidTransform T = params.initial;
  std::vector<Pair> pairs;
  bool converged = false;
  const double trim = std::clamp(params.trim_fraction, 0.05, 1.0);
  for (int it = 0; it < std::clamp(params.max_iterations, 1, 500); ++it) {
    pairs.clear();
    // The nearest fixed sample of each moving one, on all threads; the pairs in sample order.
    std::vector<int> nearest(source.points.size());
    std::vector<double> nearest_d2(source.points.size());
    parallel_for(source.points.size(), [&](size_t first, size_t last) {
      for (size_t i = first; i < last; ++i)
        nearest[i] = index.nearest(T.apply(source.points[i]), &nearest_d2[i]);
    });
    for (size_t i = 0; i < source.points.size(); ++i) {
      const Eigen::Vector3d p = T.apply(source.points[i]);
      const double d2 = nearest_d2[i];
      const int c = nearest[i];
      if (d2 > params.max_correspondence_mm * params.max_correspondence_mm) continue;
      const Eigen::Vector3d& n = fixed_samples.normals[c];
      if (n.dot(T.apply_direction(source.normals[i])) < 0.3) continue;  // outer vs inner table
      pairs.push_back({p, fixed_samples.points[c], n, n.dot(p - fixed_samples.points[c])});
    }
    if (pairs.size() < 6) {
      result.status = RegisterResult::Status::Failed;
      result.message = "too few corresponding points: the meshes do not overlap (within " +
                       std::to_string(params.max_correspondence_mm) + " mm)";
      result.iterations = it;
      result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      return result;
    }
    // Trim: keep the best fraction by |residual|.
    const size_t keep = std::max<size_t>(6, static_cast<size_t>(trim * pairs.size()));
    if (keep < pairs.size()) {
      std::nth_element(pairs.begin(), pairs.begin() + keep, pairs.end(),
                       [](const Pair& a, const Pair& b) { return std::abs(a.r) < std::abs(b.r); });
      pairs.resize(keep);
    }
    // Rotations about the pairs' centroid, not the file's origin: the steps, and so where the
    // iteration stops, are the same in any pose (about a far origin a rotation and a
    // translation nearly cancel, and the system is badly conditioned).
    Eigen::Vector3d pivot = Eigen::Vector3d::Zero();
    for (const auto& pr : pairs) pivot += pr.p;
    pivot /= static_cast<double>(pairs.size());
    Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();
    double sum2 = 0.0;
    for (const auto& pr : pairs) {
      Eigen::Matrix<double, 6, 1> J;
      J.head<3>() = (pr.p - pivot).cross(pr.n);
      J.tail<3>() = pr.n;
      const double w = std::abs(pr.r) <= params.huber_mm ? 1.0 : params.huber_mm / std::abs(pr.r);
      A += w * J * J.transpose();
      b -= w * J * pr.r;
      sum2 += pr.r * pr.r;
    }
    result.rms_mm = std::sqrt(sum2 / pairs.size());
    result.inlier_fraction = static_cast<double>(pairs.size()) / source.points.size();
    result.iterations = it + 1;
    const Eigen::Matrix<double, 6, 1> x = A.ldlt().solve(b);
    if (!x.allFinite()) {
      result.status = RegisterResult::Status::Failed;
      result.message = "the registration is degenerate (the overlap constrains too few directions)";
      return result;
    }
    const RigidTransform step = small_motion(x, pivot);
    T = step * T;
    // Largest displacement of a sample point by this step.
    double moved = 0.0;
    for (size_t i = 0; i < pairs.size(); i += std::max<size_t>(1, pairs.size() / 200))
      moved = std::max(moved, (step.apply(pairs[i].p) - pairs[i].p).norm());
    if (moved < params.convergence_mm) {
      converged = true;
      break;
    }
  }
  // Re-orthonormalise the accumulated rotation.
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(T.rotation,
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  T.rotation = svd.matrixU() * svd.matrixV().transpose();
  result.transform = T;
  result.status =
      converged ? RegisterResult::Status::Converged : RegisterResult::Status::MaxIterations;
  result.message =
      converged ? "converged" : "stopped at the iteration limit (still moving slightly)";
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

RegisterResult register_mirror(const SkullMesh& skull, const Plane& plane,
                               const RegisterParams& params, const VertexCloud* cloud) {
  const RigidTransform reflection = reflection_across(plane);
  RegisterParams own = params;
  own.initial = params.initial * reflection;
  RegisterResult result = register_icp(skull, skull, own, cloud, cloud);
  result.transform = result.transform * reflection;  // the reflection is its own inverse
  return result;
}

}  // namespace cranioplan
