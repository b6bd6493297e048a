#include "cranioplan/algorithms/planning/shape_prior.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "cranioplan/algorithms/geometry/point_index.h"
#include "cranioplan/algorithms/geometry/surface_locator.h"

namespace cranioplan {

std::string shape_prior_note(const ShapeFit& fit, bool used) {
  // A usable fit always guides the plan (propose_markers_with_model fits only where it will).
  return used ? fit.message : "not guided by the shape model: " + fit.message;
}

ShapePrior fit_shape_prior(const ShapeModel& model, const SkullMesh& skull,
                           const SurfaceLocator& bone, const DefectRegion& defect,
                           const ShapePriorParams& params) {
  ShapePrior out;
  const std::vector<Eigen::Vector3d> points = vertex_sample(skull, 40000);
  // The opening seen from the rays' centre, widened by the margin at each point's distance: a
  // point is left out when a ray through the opening passes within the margin's angle of it.
  const PointIndex holes(defect.hole_directions);
  const double margin = std::clamp(params.margin_mm, 0.0, 50.0);
  const Eigen::Vector3d center = defect.center;
  auto left_out = [&](const Eigen::Vector3d& p) {
    if (holes.size() == 0) return false;
    const Eigen::Vector3d v = p - center;
    const double r = v.norm();
    if (r <= 0.0) return false;
    double d2 = 0.0;
    holes.nearest(v / r, &d2);
    // Chord between unit directions ≈ angle; the margin's angle at distance r, plus half the
    // rays' spacing (the opening's directions are samples).
    const double angle = 2.0 * std::asin(std::min(1.0, std::sqrt(d2) / 2.0));
    return angle * r <= margin + 2.0;
  };
  out.fit = fit_shape_model(model, bone, points, left_out, params.fit);
  if (!out.fit.usable()) return out;
  out.mesh = model.mesh(out.fit.points);
  out.locator = std::make_shared<SurfaceLocator>(out.mesh);
  return out;
}

MarkerProposal propose_markers_with_model(const DefectRegion& defect, const SkullMesh& skull,
                                          const SurfaceLocator& bone, const SurfaceLocator& mirror,
                                          const ProposeParams& params, int first_id,
                                          const ShapeModel* model,
                                          const ShapePriorParams& prior_params,
                                          std::optional<ShapeFit>* fit) {
  std::optional<ShapePrior> prior;
  std::optional<ShapeFit> fitted;
  if (model && defect.found()) {
    auto skipped = [](const std::string& why) {
      ShapeFit f;
      f.status = ShapeFit::Status::Skipped;
      f.message = why;
      return f;
    };
    if (params.method == PlanMethod::Mirror || params.method == PlanMethod::RimOnly) {
      fitted = skipped(std::string("not fitted, the plan's method is ") + to_string(params.method));
    } else if (const double coverage = params.method == PlanMethod::Auto
                                           ? mirror_coverage(defect, mirror, params)
                                           : 0.0;
               params.method == PlanMethod::Auto && coverage >= params.min_mirror_coverage) {
      char text[120];
      std::snprintf(text, sizeof text, "not fitted, the mirror covers %.0f%% of the opening",
                    100.0 * coverage);
      fitted = skipped(text);
    } else {
      prior = fit_shape_prior(*model, skull, bone, defect, prior_params);
      fitted = prior->fit;
    }
  }
  MarkerProposal proposal =
      propose_markers_for_defect(defect, bone, mirror, params, first_id,
                                 prior && prior->usable() ? prior->locator.get() : nullptr);
  if (fitted)
    proposal.surfaces_message +=
        (proposal.surfaces_message.empty() ? "" : "; ") +
        shape_prior_note(*fitted, proposal.method_used == PlanMethod::ShapeModel);
  if (fit) *fit = std::move(fitted);
  return proposal;
}

}  // namespace cranioplan
