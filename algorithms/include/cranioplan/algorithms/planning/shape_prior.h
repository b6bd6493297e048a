#pragma once
// A shape model of the normal skull (shape/shape_model.h) fitted to a defective skull's intact
// bone, the opening and a margin around it left out: a prior for the missing bone's surfaces,
// read along the planner's rays as the registered mirror is (fit_defect_surfaces.h).
#include <memory>
#include <optional>
#include <string>

#include "cranioplan/algorithms/planning/detect_defect.h"
#include "cranioplan/algorithms/planning/propose_markers.h"
#include "cranioplan/algorithms/shape/fit_shape_model.h"
#include "cranioplan/model/mesh.h"

namespace cranioplan {

class SurfaceLocator;

struct ShapePriorParams {
  ShapeFitParams fit;
  /// Bone within this distance of the opening (along the skull, about) is not fitted, mm: the
  /// rim's cut face and any bone the trauma or the saw bent (0..50).
  double margin_mm = 10.0;
};

struct ShapePrior {
  ShapeFit fit;
  SkullMesh mesh;                           ///< the fitted instance's two sheets
  std::shared_ptr<SurfaceLocator> locator;  ///< over `mesh`; null unless the fit is usable
  bool usable() const { return fit.usable() && locator != nullptr; }
};

/// What a plan says of the model it was given: how well it fitted, and whether it guided the
/// surfaces (`used`) or why not (a poor fit; the mirror covering the opening).
std::string shape_prior_note(const ShapeFit& fit, bool used);

/// Fits `model` to `skull` (located by `bone`) around the opening `defect`.
ShapePrior fit_shape_prior(const ShapeModel& model, const SkullMesh& skull,
                           const SurfaceLocator& bone, const DefectRegion& defect,
                           const ShapePriorParams& params = {});

/// The markers for `defect` (propose_markers_for_defect) with `model` (may be null) as a prior.
/// The model is fitted only where the proposal will be guided by it (method ShapeModel, or Auto
/// with the mirror covering less than `min_mirror_coverage` of the opening); the note on the
/// model (shape_prior_note) ends `surfaces_message`. `fit`, when given, receives the fit, or a
/// Skipped one saying why there was none (nothing without a model or a defect).
MarkerProposal propose_markers_with_model(const DefectRegion& defect, const SkullMesh& skull,
                                          const SurfaceLocator& bone, const SurfaceLocator& mirror,
                                          const ProposeParams& params, int first_id,
                                          const ShapeModel* model,
                                          const ShapePriorParams& prior_params = {},
                                          std::optional<ShapeFit>* fit = nullptr);

}  // namespace cranioplan
