#include "cranioplan/algorithms/alignment/fit_sagittal_plane.h"

#include <ceres/ceres.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>

#include "cranioplan/algorithms/geometry/point_index.h"
#include "cranioplan/algorithms/geometry/surface_samples.h"
#include "cranioplan/model/parallel.h"

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

// Sample p (normal m) reflected across the plane to q, and the surface sample c nearest q;
// `facing` when p's mirrored normal agrees with c's normal (not the outer table mirrored onto
// the inner one).
struct MirrorMatch {
  Eigen::Vector3d q;
  int c;
  double d2;  ///< |q − c|², mm²
  bool facing;
};

MirrorMatch mirror_match(const Eigen::Vector3d& p, const Eigen::Vector3d& m, const Plane& plane,
                         const PointIndex& index, const std::vector<Eigen::Vector3d>& normals) {
  MirrorMatch out;
  out.q = plane.reflect(p);
  out.c = index.nearest(out.q, &out.d2);
  const Eigen::Vector3d mirrored_normal = m - 2.0 * plane.normal.dot(m) * plane.normal;
  out.facing = mirrored_normal.dot(normals[out.c]) >= 0.3;
  return out;
}

// Correspondences of reflected samples on the original surface, rejecting far ones and ones
// whose mirrored normal disagrees with the surface normal (outer vs inner table of the skull).
std::vector<Correspondence> find_correspondences(const SurfaceSamples& samples,
                                                 const PointIndex& index,
                                                 const std::vector<Eigen::Vector3d>& normals,
                                                 const Plane& plane, double max_dist) {
  std::vector<Correspondence> out;
  out.reserve(samples.points.size());
  // Each sample's match on all threads; the correspondences in sample order.
  std::vector<MirrorMatch> matches(samples.points.size());
  parallel_for(samples.points.size(), [&](size_t first, size_t last) {
    for (size_t i = first; i < last; ++i)
      matches[i] = mirror_match(samples.points[i], samples.normals[i], plane, index, normals);
  });
  for (size_t i = 0; i < samples.points.size(); ++i) {
    const MirrorMatch& mm = matches[i];
    if (mm.d2 > max_dist * max_dist || !mm.facing) continue;
    out.push_back({samples.points[i], index.points()[mm.c], normals[mm.c]});
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
  std::vector<int> nearest(samples.points.size());
  std::vector<double> nearest_d2(samples.points.size());
  parallel_for(samples.points.size(), [&](size_t first, size_t last) {
    for (size_t i = first; i < last; ++i)
      nearest[i] = index.nearest(plane.reflect(samples.points[i]), &nearest_d2[i]);
  });
  for (size_t i = 0; i < samples.points.size(); ++i) {
    const Eigen::Vector3d q = plane.reflect(samples.points[i]);
    const double d2 = nearest_d2[i];
    const int c = nearest[i];
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

namespace {

// How far the mirrored surface lies from the surface, for one candidate plane. Each probe is
// reflected; its distance is to the tangent plane of the nearest sparse sample when that is near
// (within kTangentReach) and faces the same way as the mirrored probe, else to the sample itself,
// so that a sparse index has no distance floor. The score is the 80th percentile: the median
// ignores the face and the back of the head, which are what tell the midsagittal plane from a
// coronal one through a round head; the top fifth is left for the defect and its mirror.
class SymmetryScore {
 public:
  SymmetryScore(const SurfaceSamples& all, const Eigen::Vector3d& centroid)
      : sparse_(subsample(all, 30000)),
        probe_(subsample(all, 300)),
        index_(sparse_.points),
        centroid_(centroid) {}

  // The score, or infinity as soon as it is sure to exceed `bound`: when more probes than the
  // top fifth lie further than `bound`, the 80th percentile does too. A caller that keeps a
  // plane only when its score is below the best so far (never on a tie: a score equal to the
  // bound is computed in full) chooses the same planes with or without the bound, and gives
  // up on a poor plane long before its last probe.
  double operator()(const Plane& plane,
                    double bound = std::numeric_limits<double>::infinity()) const {
    const size_t n = probe_.points.size();
    const size_t rank = static_cast<size_t>(0.8 * static_cast<double>(n));
    const size_t above_needed = n - rank;  // probes beyond `bound` that put the score there
    size_t above = 0;
    std::vector<double> d;
    d.reserve(n);
    for (size_t i = 0; i < n; ++i) {
      const MirrorMatch mm =
          mirror_match(probe_.points[i], probe_.normals[i], plane, index_, sparse_.normals);
      double dist = std::sqrt(mm.d2);
      if (dist < kTangentReach && mm.facing)
        dist = std::abs(sparse_.normals[mm.c].dot(mm.q - sparse_.points[mm.c]));
      d.push_back(dist);
      if (dist > bound && ++above == above_needed) return std::numeric_limits<double>::infinity();
    }
    const auto at = d.begin() + static_cast<std::ptrdiff_t>(rank);
    std::nth_element(d.begin(), at, d.end());
    return *at;
  }

  // The best plane with normal `n` among offsets `centre` + k·step, k = −count..count (on equal
  // scores the lowest k). The centre first: it is most often the best, and bounds the others.
  // `*score` is infinity when every offset scores above `bound`.
  Plane best_offset(const Eigen::Vector3d& n, double centre, double step, int count, double* score,
                    double bound = std::numeric_limits<double>::infinity()) const {
    int best_k = 0;
    *score = (*this)(Plane{n, centre}, bound);
    for (int k = -count; k <= count; ++k) {
      if (k == 0) continue;
      const double sc = (*this)(Plane{n, centre + k * step}, std::min(bound, *score));
      if (sc < *score || (sc == *score && k < best_k)) *score = sc, best_k = k;
    }
    return Plane{n, centre + best_k * step};
  }

  const Eigen::Vector3d& centroid() const { return centroid_; }

 private:
  static constexpr double kTangentReach = 3.0;  // mm
  SurfaceSamples sparse_, probe_;
  PointIndex index_;
  Eigen::Vector3d centroid_;
};

struct Candidate {
  Plane plane;
  double score;
};

// Pattern search on the plane's tilt (8 directions, turning about the plane's point nearest the
// centroid, so a skull far from the origin turns in place) and its offset, with steps of 4°
// and 2 mm down to 0.25° and 0.125 mm; each round takes the best of the 10 moves.
Candidate polish(const SymmetryScore& score, Candidate c) {
  for (double step_deg = 4.0; step_deg >= 0.25; step_deg /= 2) {
    const double step_mm = 0.5 * step_deg;
    for (int round = 0; round < 12; ++round) {
      const Eigen::Vector3d pivot = c.plane.project(score.centroid());
      const Eigen::Vector3d e1 = c.plane.normal.unitOrthogonal(), e2 = c.plane.normal.cross(e1);
      Candidate next = c;
      auto consider = [&](const Plane& p) {
        const double sc = score(p, next.score);
        if (sc < next.score) next = {p, sc};
      };
      for (int a = 0; a < 8; ++a) {
        const Eigen::Vector3d axis = std::cos(a * M_PI / 4) * e1 + std::sin(a * M_PI / 4) * e2;
        const Eigen::Vector3d n = Eigen::AngleAxisd(step_deg * M_PI / 180.0, axis) * c.plane.normal;
        consider(Plane{n, n.dot(pivot)});
      }
      consider(Plane{c.plane.normal, c.plane.offset + step_mm});
      consider(Plane{c.plane.normal, c.plane.offset - step_mm});
      if (next.score >= c.score) break;
      c = next;
    }
  }
  return c;
}

}  // namespace

Plane automatic_initial_plane(const SkullMesh& mesh) {
  return automatic_initial_plane(all_vertex_samples(mesh));
}

Plane automatic_initial_plane(const SurfaceSamples& all) {
  return automatic_initial_plane(all, InitialPlaneParams{}).plane;
}

InitialPlaneResult automatic_initial_plane(const SurfaceSamples& all,
                                           const InitialPlaneParams& params) {
  assert(!all.points.empty());
  assert(params.first_pass_stride >= 1);
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& p : all.points) centroid += p;
  centroid /= static_cast<double>(all.points.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& p : all.points) cov += (p - centroid) * (p - centroid).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);

  // Candidate normals: 200 spread evenly over the half sphere (about 10° apart; a normal and its
  // opposite are the same plane), the principal axes and the file's axes. A skull is nearly as
  // wide as it is high, so its principal axes can lie 20° or more off the midsagittal normal,
  // and in an unseen pose the file's axes mean nothing.
  // The first half of a Fibonacci sphere of 400 is its upper half (z > 0).
  constexpr int kSpread = 200;
  std::vector<Eigen::Vector3d> normals = fibonacci_sphere(2 * kSpread);
  normals.resize(kSpread);
  for (int k = 0; k < 3; ++k) normals.push_back(eig.eigenvectors().col(k));
  for (int k = 0; k < 3; ++k) normals.push_back(Eigen::Vector3d::Unit(k));

  // Each through the centroid or up to 6 mm beside it: a defect on one side moves the centroid
  // off the midsagittal plane. Then the best candidate of each basin (candidates more than 20°
  // apart), up to six basins, is polished and the best polished one wins: a candidate a few
  // degrees off the midsagittal normal mirrors the far side of the head millimetres off and can
  // rank below a wrong plane through a round head until it is polished.
  const SymmetryScore score(all, centroid);
  // The candidates and the basins' polishing on all threads, each result in its own place and
  // compared in order afterwards.
  //
  // Only the candidates up to the sixth basin's matter. Every params.first_pass_stride-th of
  // them (a quarter by default) and the axes are scored first; their sixth basin's score bounds
  // the rest, whose scores are given up as soon as they are sure to exceed it (SymmetryScore).
  // When the six basins of all the candidates then lie within the bound, they are the basins
  // every candidate scored in full gives (no given-up candidate can rank before them); otherwise
  // the given-up ones are scored in full.
  std::vector<Candidate> candidates(normals.size());
  auto score_candidates = [&](const std::vector<size_t>& which, double bound) {
    parallel_for(
        which.size(),
        [&](size_t first, size_t last) {
          for (size_t w = first; w < last; ++w) {
            const size_t i = which[w];
            double sc;
            const Plane p =
                score.best_offset(normals[i], normals[i].dot(centroid), 3.0, 2, &sc, bound);
            candidates[i] = {p, sc};
          }
        },
        8);
  };
  const double apart = std::cos(20.0 * M_PI / 180.0);
  // The best candidate of each basin, up to six, best first (on equal scores the first normal).
  auto basins_of = [&](std::vector<size_t> which) {
    std::sort(which.begin(), which.end(), [&](size_t a, size_t b) {
      return candidates[a].score < candidates[b].score ||
             (candidates[a].score == candidates[b].score && a < b);
    });
    std::vector<Candidate> basins;
    for (size_t i : which) {
      const Candidate& c = candidates[i];
      if (basins.size() == 6) break;
      const bool new_basin = std::none_of(basins.begin(), basins.end(), [&](const Candidate& b) {
        return std::abs(b.plane.normal.dot(c.plane.normal)) > apart;
      });
      if (new_basin) basins.push_back(c);
    }
    return basins;
  };
  InitialPlaneResult result;
  result.candidates = normals.size();
  const size_t stride = static_cast<size_t>(params.first_pass_stride);
  std::vector<size_t> first_pass, rest, all_candidates(normals.size());
  for (size_t i = 0; i < normals.size(); ++i) {
    all_candidates[i] = i;
    (i % stride == 0 || i >= static_cast<size_t>(kSpread) ? first_pass : rest).push_back(i);
  }
  score_candidates(first_pass, std::numeric_limits<double>::infinity());
  const std::vector<Candidate> first_basins = basins_of(first_pass);
  const double bound = first_basins.size() == 6 ? first_basins.back().score
                                                : std::numeric_limits<double>::infinity();
  score_candidates(rest, bound);
  std::vector<size_t> given_up;
  for (size_t i : rest)
    if (candidates[i].score == std::numeric_limits<double>::infinity()) given_up.push_back(i);
  result.given_up = given_up.size();
  std::vector<Candidate> basins = basins_of(all_candidates);
  if (basins.size() < 6 || basins.back().score > bound) {
    score_candidates(given_up, std::numeric_limits<double>::infinity());
    result.rescored = given_up.size();
    basins = basins_of(all_candidates);
  }
  std::vector<Candidate> polished(basins.size());
  parallel_for(
      basins.size(),
      [&](size_t first, size_t last) {
        for (size_t i = first; i < last; ++i) polished[i] = polish(score, basins[i]);
      },
      1);
  // (The first candidate in order always opens a basin.)
  Candidate best{basins.front().plane, std::numeric_limits<double>::infinity()};
  for (const Candidate& c : polished)
    if (c.score < best.score) best = c;
  Plane plane = best.plane;
  // Orient the normal along the positive coordinate axis it is closest to, for stable output.
  int axis;
  plane.normal.cwiseAbs().maxCoeff(&axis);
  if (plane.normal[axis] < 0) plane = plane.flipped();
  result.plane = plane;
  return result;
}

PlaneFit fit_sagittal_plane(const SkullMesh& mesh, const Landmarks& landmarks,
                            const PlaneFitParams& params, const VertexCloud* cloud) {
  const auto t0 = std::chrono::steady_clock::now();
  PlaneFit fit;
  if (mesh.n_vertices() < 10 && !landmarks.has_required()) {
    fit.message = "the mesh has too few vertices and no landmarks were given";
    return fit;
  }
  if (landmarks.has_required()) {
    fit.initial = initial_plane_from_landmarks(landmarks);
    fit.initial_method = "landmarks";
  }
  const bool use_surface = params.use_surface_symmetry && mesh.n_vertices() >= 10;
  std::unique_ptr<VertexCloud> own;
  if (!cloud && (use_surface || !landmarks.has_required()))
    cloud = (own = std::make_unique<VertexCloud>(mesh)).get();
  if (!landmarks.has_required()) {
    fit.initial = automatic_initial_plane(cloud->samples);
    fit.initial_method = "automatic";
  }
  fit.plane = fit.initial;

  const SurfaceSamples empty;
  const SurfaceSamples& all = use_surface ? cloud->samples : empty;
  const PointIndex* index = use_surface ? &cloud->index : nullptr;
  SurfaceSamples samples;
  if (use_surface)
    samples = subsample(all, static_cast<size_t>(std::clamp(params.sample_count, 100, 100000)));

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
        const bool coarse = it < params.coarse_iterations;
        ceres::LossFunction* loss =  // shared by the residuals
            new ceres::CauchyLoss(coarse ? params.coarse_robust_scale_mm : params.robust_scale_mm);
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
      converged = it >= params.coarse_iterations &&
                  after.angle_to_deg(before) < params.convergence_deg &&
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
