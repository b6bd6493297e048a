#include "cranioplan/algorithms/fit_sagittal_plane.h"

#include <ceres/ceres.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>

#include "cranioplan/algorithms/point_index.h"
#include "cranioplan/algorithms/surface_samples.h"

namespace cranioplan {
namespace {

// Residual of one surface sample p: its reflection across the plane (n, d) must lie on the
// tangent plane of its correspondence c (normal m) on the original surface.
struct SymmetryCost {
  SymmetryCost(const Eigen::Vector3d& p, const Eigen::Vector3d& c, const Eigen::Vector3d& m)
      : p_(p), c_(c), m_(m) {}
  template <typename T>
  bool operator()(const T* n, const T* d, T* residual) const {
    const T s = n[0] * p_.x() + n[1] * p_.y() + n[2] * p_.z() - d[0];
    T r = T(0);
    for (int k = 0; k < 3; ++k) r += m_[k] * (p_[k] - T(2) * s * n[k] - c_[k]);
    residual[0] = r;
    return true;
  }
  static ceres::CostFunction* Create(const Eigen::Vector3d& p, const Eigen::Vector3d& c,
                                     const Eigen::Vector3d& m) {
    return new ceres::AutoDiffCostFunction<SymmetryCost, 1, 3, 1>(new SymmetryCost(p, c, m));
  }
  Eigen::Vector3d p_, c_, m_;
};

// The left orbit centre reflected across the plane must land on the right one.
struct OrbitCost {
  OrbitCost(const Eigen::Vector3d& left, const Eigen::Vector3d& right, double w)
      : l_(left), r_(right), w_(w) {}
  template <typename T>
  bool operator()(const T* n, const T* d, T* residual) const {
    const T s = n[0] * l_.x() + n[1] * l_.y() + n[2] * l_.z() - d[0];
    for (int k = 0; k < 3; ++k) residual[k] = T(w_) * (l_[k] - T(2) * s * n[k] - r_[k]);
    return true;
  }
  static ceres::CostFunction* Create(const Eigen::Vector3d& l, const Eigen::Vector3d& r, double w) {
    return new ceres::AutoDiffCostFunction<OrbitCost, 3, 3, 1>(new OrbitCost(l, r, w));
  }
  Eigen::Vector3d l_, r_;
  double w_;
};

// A midline landmark must lie on the plane.
struct MidlineCost {
  MidlineCost(const Eigen::Vector3d& p, double w) : p_(p), w_(w) {}
  template <typename T>
  bool operator()(const T* n, const T* d, T* residual) const {
    residual[0] = T(w_) * (n[0] * p_.x() + n[1] * p_.y() + n[2] * p_.z() - d[0]);
    return true;
  }
  static ceres::CostFunction* Create(const Eigen::Vector3d& p, double w) {
    return new ceres::AutoDiffCostFunction<MidlineCost, 1, 3, 1>(new MidlineCost(p, w));
  }
  Eigen::Vector3d p_;
  double w_;
};

std::vector<Eigen::Vector3d> midline_points(const Landmarks& lm) {
  std::vector<Eigen::Vector3d> pts;
  if (lm.nasion) pts.push_back(*lm.nasion);
  pts.insert(pts.end(), lm.midline.begin(), lm.midline.end());
  return pts;
}

void add_landmark_residuals(ceres::Problem& problem, const Landmarks& lm, double weight, double* n,
                            double* d) {
  if (weight <= 0) return;
  if (lm.orbit_left && lm.orbit_right)
    problem.AddResidualBlock(OrbitCost::Create(*lm.orbit_left, *lm.orbit_right, weight), nullptr, n,
                             d);
  for (const auto& p : midline_points(lm))
    problem.AddResidualBlock(MidlineCost::Create(p, weight), nullptr, n, d);
}

struct Correspondence {
  Eigen::Vector3d p, c, m;
};

// Correspondences of reflected samples on the original surface, rejecting far ones and ones
// whose mirrored normal disagrees with the surface normal (outer vs inner table of the skull).
std::vector<Correspondence> find_correspondences(const SurfaceSamples& samples,
                                                 const PointIndex& index,
                                                 const std::vector<Eigen::Vector3d>& normals,
                                                 const Plane& plane, double max_dist) {
  std::vector<Correspondence> out;
  out.reserve(samples.points.size());
  for (size_t i = 0; i < samples.points.size(); ++i) {
    const Eigen::Vector3d q = plane.reflect(samples.points[i]);
    double d2;
    const int c = index.nearest(q, &d2);
    if (d2 > max_dist * max_dist) continue;
    const Eigen::Vector3d& np = samples.normals[i];
    const Eigen::Vector3d mirrored_normal = np - 2.0 * plane.normal.dot(np) * plane.normal;
    if (mirrored_normal.dot(normals[c]) < 0.3) continue;
    out.push_back({samples.points[i], index.points()[c], normals[c]});
  }
  return out;
}

struct SymmetryMeasure {
  double rms = 0.0;
  double inlier_fraction = 0.0;
  double median_distance = 0.0;
};

SymmetryMeasure measure_symmetry(const SurfaceSamples& samples, const PointIndex& index,
                                 const std::vector<Eigen::Vector3d>& normals, const Plane& plane,
                                 double max_dist, double inlier_mm) {
  SymmetryMeasure m;
  if (samples.points.empty()) return m;
  std::vector<double> dists;
  dists.reserve(samples.points.size());
  double sum2 = 0.0;
  size_t inliers = 0;
  for (size_t i = 0; i < samples.points.size(); ++i) {
    const Eigen::Vector3d q = plane.reflect(samples.points[i]);
    double d2;
    const int c = index.nearest(q, &d2);
    dists.push_back(std::sqrt(d2));
    if (d2 > max_dist * max_dist) continue;
    const double r = normals[c].dot(q - index.points()[c]);
    if (std::abs(r) < inlier_mm) {
      sum2 += r * r;
      ++inliers;
    }
  }
  std::nth_element(dists.begin(), dists.begin() + dists.size() / 2, dists.end());
  m.median_distance = dists[dists.size() / 2];
  m.inlier_fraction = static_cast<double>(inliers) / samples.points.size();
  m.rms = inliers ? std::sqrt(sum2 / inliers) : 0.0;
  return m;
}

}  // namespace

Plane initial_plane_from_landmarks(const Landmarks& lm) {
  assert(lm.has_required() && "initial_plane_from_landmarks needs nasion and both orbits");
  const Eigen::Vector3d axis = *lm.orbit_right - *lm.orbit_left;
  Plane plane = Plane::through(0.5 * (*lm.orbit_left + *lm.orbit_right), axis);
  // Through the orbit midpoint and the nasion on average.
  plane.offset = 0.5 * (plane.offset + plane.normal.dot(*lm.nasion));
  if (lm.midline.empty()) return plane;

  double n[3] = {plane.normal.x(), plane.normal.y(), plane.normal.z()};
  double d = plane.offset;
  ceres::Problem problem;
  add_landmark_residuals(problem, lm, 1.0, n, &d);
  problem.SetManifold(n, new ceres::SphereManifold<3>());
  ceres::Solver::Options options;
  options.max_num_iterations = 50;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  if (!summary.IsSolutionUsable()) return plane;
  return Plane{Eigen::Vector3d(n[0], n[1], n[2]).normalized(), d};
}

Plane automatic_initial_plane(const SkullMesh& mesh) {
  const SurfaceSamples all = all_vertex_samples(mesh);
  assert(!all.points.empty());
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& p : all.points) centroid += p;
  centroid /= static_cast<double>(all.points.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& p : all.points) cov += (p - centroid) * (p - centroid).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);

  std::vector<Eigen::Vector3d> candidates;
  for (int k = 0; k < 3; ++k) candidates.push_back(eig.eigenvectors().col(k));
  for (int k = 0; k < 3; ++k) candidates.push_back(Eigen::Vector3d::Unit(k));

  const PointIndex index(all.points);
  const SurfaceSamples probe = subsample(all, 600);  // 6 axes x 25 offsets are scored
  Plane best = Plane::through(centroid, candidates[0]);
  double best_score = std::numeric_limits<double>::infinity();
  // Each candidate's offset is searched too: a defect on one side moves the centroid off the
  // midsagittal plane (by a millimetre or more), and a plane through it mirrors everything twice
  // that far off — enough for a wrong axis to score better.
  auto score = [&](const Eigen::Vector3d& n, double offset) {
    return measure_symmetry(probe, index, all.normals, Plane{n, offset}, 1e9, 1.0).median_distance;
  };
  for (const auto& n : candidates) {
    const double d0 = n.dot(centroid);
    double best_d = d0, best_s = score(n, d0);
    for (double step : {2.0, 0.5}) {
      const double centre = best_d;
      for (int k = -6; k <= 6; ++k) {
        if (k == 0) continue;
        const double d = centre + k * step;
        const double sc = score(n, d);
        if (sc < best_s) best_s = sc, best_d = d;
      }
    }
    if (best_s < best_score) {
      best_score = best_s;
      best = Plane{n, best_d};
    }
  }
  // Orient the normal along the positive coordinate axis it is closest to, for stable output.
  int axis;
  best.normal.cwiseAbs().maxCoeff(&axis);
  if (best.normal[axis] < 0) best = best.flipped();
  return best;
}

PlaneFit fit_sagittal_plane(const SkullMesh& mesh, const Landmarks& landmarks,
                            const PlaneFitParams& params) {
  const auto t0 = std::chrono::steady_clock::now();
  PlaneFit fit;
  if (mesh.n_vertices() < 10 && !landmarks.has_required()) {
    fit.message = "the mesh has too few vertices and no landmarks were given";
    return fit;
  }
  if (landmarks.has_required()) {
    fit.initial = initial_plane_from_landmarks(landmarks);
    fit.initial_method = "landmarks";
  } else {
    fit.initial = automatic_initial_plane(mesh);
    fit.initial_method = "automatic";
  }
  fit.plane = fit.initial;

  const bool use_surface = params.use_surface_symmetry && mesh.n_vertices() >= 10;
  SurfaceSamples all, samples;
  std::unique_ptr<PointIndex> index;
  if (use_surface) {
    all = all_vertex_samples(mesh);
    samples = subsample(all, static_cast<size_t>(std::clamp(params.sample_count, 100, 100000)));
    index = std::make_unique<PointIndex>(all.points);
  }

  fit.status = PlaneFit::Status::Converged;
  if (params.refine && (use_surface || landmarks.has_required())) {
    double n[3] = {fit.plane.normal.x(), fit.plane.normal.y(), fit.plane.normal.z()};
    double d = fit.plane.offset;
    const int outer = use_surface ? std::clamp(params.outer_iterations, 1, 50) : 1;
    bool converged = false;
    for (int it = 0; it < outer && !converged; ++it) {
      const Plane before{Eigen::Vector3d(n[0], n[1], n[2]), d};
      ceres::Problem problem;
      add_landmark_residuals(problem, landmarks, params.landmark_weight, n, &d);
      size_t used = 0;
      if (use_surface) {
        const auto corr = find_correspondences(samples, *index, all.normals, before,
                                               params.max_correspondence_mm);
        ceres::LossFunction* loss = new ceres::CauchyLoss(params.robust_scale_mm);  // shared
        for (const auto& c : corr)
          problem.AddResidualBlock(SymmetryCost::Create(c.p, c.c, c.m), loss, n, &d);
        used = corr.size();
      }
      if (problem.NumResidualBlocks() == 0 ||
          (use_surface && used < 10 && !landmarks.has_required())) {
        fit.status = PlaneFit::Status::Failed;
        fit.message =
            "too few symmetric correspondences: the initial plane is far from the "
            "midline (give nasion and orbit landmarks)";
        break;
      }
      problem.SetManifold(n, new ceres::SphereManifold<3>());
      ceres::Solver::Options options;
      options.max_num_iterations = 25;
      options.linear_solver_type = ceres::DENSE_QR;
      ceres::Solver::Summary summary;
      ceres::Solve(options, &problem, &summary);
      fit.iterations = it + 1;
      fit.solver_iterations += static_cast<int>(summary.iterations.size());
      fit.termination = ceres::TerminationTypeToString(summary.termination_type);
      if (!summary.IsSolutionUsable()) {
        fit.status = PlaneFit::Status::Failed;
        fit.message = "Ceres could not solve: " + summary.message;
        break;
      }
      const Plane after{Eigen::Vector3d(n[0], n[1], n[2]).normalized(), d};
      converged = after.angle_to_deg(before) < params.convergence_deg &&
                  std::abs(after.offset - before.offset) < params.convergence_mm;
      fit.plane = after;
    }
    if (fit.status != PlaneFit::Status::Failed) {
      fit.status =
          converged || !use_surface ? PlaneFit::Status::Converged : PlaneFit::Status::MaxIterations;
      fit.message = converged || !use_surface
                        ? "converged"
                        : "stopped after " + std::to_string(fit.iterations) +
                              " correspondence updates (plane still moving slightly)";
    }
  } else {
    fit.message = "initial plane (no refinement)";
  }
  // Keep the normal's orientation from the initial plane (left → right for landmarks).
  if (fit.plane.normal.dot(fit.initial.normal) < 0) fit.plane = fit.plane.flipped();
  if (use_surface) {
    const SymmetryMeasure m =
        measure_symmetry(samples, *index, all.normals, fit.plane, params.max_correspondence_mm,
                         params.inlier_threshold_mm);
    fit.symmetry_rms_mm = m.rms;
    fit.inlier_fraction = m.inlier_fraction;
  }
  fit.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return fit;
}

}  // namespace cranioplan
