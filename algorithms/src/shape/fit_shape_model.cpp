#include "cranioplan/algorithms/shape/fit_shape_model.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "cranioplan/algorithms/geometry/surface_locator.h"

namespace cranioplan {
namespace {

// The vertices whose posed position is not left out.
std::vector<Eigen::Index> kept_vertices(const Eigen::Matrix3Xd& posed,
                                        const std::function<bool(const Eigen::Vector3d&)>& out) {
  std::vector<Eigen::Index> keep;
  for (Eigen::Index i = 0; i < posed.cols(); ++i)
    if (!out || !out(posed.col(i))) keep.push_back(i);
  return keep;
}

}  // namespace

const char* status_name(ShapeFit::Status status) {
  switch (status) {
    case ShapeFit::Status::Fitted:
      return "fitted";
    case ShapeFit::Status::Poor:
      return "poor";
    case ShapeFit::Status::Skipped:
      return "skipped";
    case ShapeFit::Status::Failed:
      break;
  }
  return "failed";
}

ShapeFit fit_shape_model(const ShapeModel& model, const SurfaceLocator& bone,
                         const std::vector<Eigen::Vector3d>& bone_points,
                         const std::function<bool(const Eigen::Vector3d&)>& left_out,
                         const ShapeFitParams& params) {
  ShapeFit r;
  const Eigen::Index n = model.vertex_count(), k = model.component_count();
  if (n == 0) {
    r.message = "the shape model has no vertices";
    return r;
  }
  r.coefficients = Eigen::VectorXd::Zero(k);
  Eigen::Matrix3Xd shape = model.instance(r.coefficients);
  // The pose: from 24 rotations on every vertex (the opening's are not yet known in the model's
  // frame; trimming drops most of them), then again without the ones left out.
  const AlignResult first = align_to_surface(shape, sheet_normals(model.triangles, shape), bone,
                                             bone_points, params.align);
  if (!std::isfinite(first.rms_mm)) {
    r.message = "the shape model could not be placed on the skull";
    return r;
  }
  Similarity T = first.transform;
  double rms = 0.0, paired = 0.0;
  for (int it = 0; it < params.iterations; ++it) {
    const Eigen::Matrix3Xd normals = sheet_normals(model.triangles, shape);
    const std::vector<Eigen::Index> keep = kept_vertices(apply_similarity(T, shape), left_out);
    if (keep.empty()) break;
    const SurfacePairs p = pair_with_surface(shape, normals, keep, T, bone, params.max_distance_mm,
                                             params.max_normal_angle_deg);
    if (p.index.size() < 50) {
      r.message = "the shape model pairs with too little of the skull's bone";
      return r;
    }
    const double limit = std::max(2.0, 3.0 * median_of(p.distance));
    std::vector<size_t> used;
    double sq = 0.0;
    for (size_t j = 0; j < p.index.size(); ++j)
      if (p.distance[j] <= limit) {
        used.push_back(j);
        sq += p.distance[j] * p.distance[j];
      }
    rms = std::sqrt(sq / std::max<size_t>(1, used.size()));
    paired = static_cast<double>(used.size()) / keep.size();
    // The similarity of the current shape onto the pairs.
    Eigen::Matrix3Xd a(3, used.size()), b(3, used.size());
    for (size_t j = 0; j < used.size(); ++j) {
      a.col(j) = shape.col(p.index[used[j]]);
      b.col(j) = p.target[used[j]];
    }
    T = similarity_between(a, b, Eigen::VectorXd::Ones(used.size()), true);
    if (k == 0) continue;
    // The coefficients: the pairs brought into the model's frame, fitted with the prior.
    const Eigen::Matrix3d sR = T.topLeftCorner<3, 3>();
    const Eigen::Matrix3d inv = sR.inverse();
    Eigen::MatrixXd A(3 * used.size(), k);
    Eigen::VectorXd y(3 * used.size());
    for (size_t j = 0; j < used.size(); ++j) {
      const Eigen::Index v = p.index[used[j]];
      A.middleRows(3 * j, 3) = model.components.middleRows(3 * v, 3);
      y.segment<3>(3 * j) =
          inv * (b.col(j) - T.topRightCorner<3, 1>()) - model.mean.segment<3>(3 * v);
    }
    const double noise2 = params.noise_mm * params.noise_mm;
    Eigen::MatrixXd N = A.transpose() * A;
    for (Eigen::Index c = 0; c < k; ++c) N(c, c) += noise2 / std::max(1e-9, model.variances(c));
    const Eigen::VectorXd before = r.coefficients;
    r.coefficients = N.ldlt().solve(A.transpose() * y);
    shape = model.instance(r.coefficients);
    // Settled: no coefficient moved by a hundredth of its standard deviation.
    if (((r.coefficients - before).array() / model.variances.array().max(1e-18).sqrt())
            .abs()
            .maxCoeff() < 0.01)
      break;
  }
  r.pose = T;
  r.points = apply_similarity(T, shape);
  r.rms_mm = rms;
  r.paired = paired;
  r.mahalanobis =
      k > 0 ? (r.coefficients.array() / model.variances.array().sqrt()).matrix().norm() : 0.0;
  char text[200];
  std::snprintf(text, sizeof text,
                "the shape model fits the intact bone to %.2f mm RMS (%.0f%% of its vertices "
                "there paired)",
                r.rms_mm, 100.0 * r.paired);
  r.message = text;
  r.status = (r.rms_mm <= params.max_rms_mm && r.paired >= params.min_paired)
                 ? ShapeFit::Status::Fitted
                 : ShapeFit::Status::Poor;
  if (r.status == ShapeFit::Status::Poor) r.message += ": too poor a fit to use";
  return r;
}

}  // namespace cranioplan
