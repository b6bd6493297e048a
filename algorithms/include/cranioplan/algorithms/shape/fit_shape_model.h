#pragma once
// A shape model (shape_model.h) fitted to a skull's intact bone: a similarity first (from 24
// rotations, as the model's skulls were aligned), then the shape coefficients with the model's
// prior (a maximum a posteriori fit: the closest-point residuals against the coefficients'
// variances), the pairing and both fits repeated. Vertices the caller leaves out (the opening
// and a margin) never pair, so the model's surface over the opening is what the intact bone and
// the model's statistics predict there. A small smooth residual towards the bone around the
// opening is left to the planner, which corrects any prior to the ring
// (fit_defect_surfaces.h).
#include <Eigen/Core>
#include <functional>
#include <string>

#include "cranioplan/algorithms/shape/correspond_skull.h"
#include "cranioplan/algorithms/shape/shape_model.h"

namespace cranioplan {

class SurfaceLocator;

struct ShapeFitParams {
  AlignParams align;
  int iterations = 12;           ///< pairing and fitting rounds
  double max_distance_mm = 6.0;  ///< pairs further apart are not used
  double max_normal_angle_deg = 60.0;
  /// The noise the pairs are taken to have, mm (σ of each coordinate): the prior's weight
  /// against the data. Larger: the fit keeps nearer the mean shape.
  double noise_mm = 1.0;
  /// A fit whose residual on the intact bone (RMS over the pairs) exceeds this is poor, mm: a
  /// model that does not describe the skull where it is seen does not know the missing part.
  /// The limit lies between the fits that lay the model on the bone and those that made a plan
  /// worse (the fits it was drawn from: docs/SHAPE_MODEL.md, "Fallback").
  double max_rms_mm = 0.8;
  /// A fit that pairs fewer of the model's vertices left in than this share is poor. Pairing
  /// alone does not judge a fit: a model reaching past the scan's bone pairs less without
  /// fitting worse (docs/SHAPE_MODEL.md, "Fallback").
  double min_paired = 0.75;
};

struct ShapeFit {
  /// Skipped: not fitted, the plan did not need it (`message` says why).
  enum class Status { Fitted, Poor, Failed, Skipped };
  Status status = Status::Failed;
  std::string message;
  Eigen::Matrix3Xd points;                   ///< the fitted instance in the skull's frame
  Eigen::VectorXd coefficients;              ///< b, mm
  Similarity pose = Similarity::Identity();  ///< model frame → skull frame
  double rms_mm = 0.0;                       ///< residual on the intact bone (pairs used)
  double paired = 0.0;                       ///< share of the vertices left in that paired
  double mahalanobis = 0.0;                  ///< |b| in units of the prior's σ
  bool usable() const { return status == Status::Fitted; }
  /// Whether the residual, the pairing and the Mahalanobis distance were measured (fitted, well
  /// or poorly).
  bool measured() const { return status == Status::Fitted || status == Status::Poor; }
};
/// "fitted", "poor", "failed" or "skipped".
const char* status_name(ShapeFit::Status status);

/// Fits `model` to the surface `bone` (the skull's vertices `bone_points` for the starting
/// pose). `left_out(p)` says whether a point of the skull's frame lies in the region not to fit
/// (the opening and its margin); may be null.
ShapeFit fit_shape_model(const ShapeModel& model, const SurfaceLocator& bone,
                         const std::vector<Eigen::Vector3d>& bone_points,
                         const std::function<bool(const Eigen::Vector3d&)>& left_out,
                         const ShapeFitParams& params = {});

}  // namespace cranioplan
