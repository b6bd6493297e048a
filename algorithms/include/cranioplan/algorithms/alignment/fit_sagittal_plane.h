#pragma once
// The midsagittal plane: an initial plane from landmarks (or found automatically), refined with
// Ceres from landmarks and surface symmetry.
#include <string>

#include "cranioplan/model/landmarks.h"
#include "cranioplan/model/mesh.h"
#include "cranioplan/model/param_spec.h"
#include "cranioplan/model/plane.h"

namespace cranioplan {

struct SurfaceSamples;
struct VertexCloud;

// The fields' ranges and units are declared in for_each_field below.
struct PlaneFitParams {
  bool refine = true;                ///< run the Ceres refinement after the initial plane
  bool use_surface_symmetry = true;  ///< add the surface-symmetry residuals (needs a mesh)
  int sample_count = 4000;           ///< surface samples for symmetry
  int outer_iterations = 40;         ///< correspondence updates (k-d tree)
  double robust_scale_mm = 1.0;      ///< Cauchy loss scale for symmetry residuals
  /// The first `coarse_iterations` updates use this wider scale (graduated: the cost is smoother
  /// there, so starts a fraction of a degree apart reach the same optimum instead of stopping
  /// in different shallow minima of the nearest-point correspondences).
  double coarse_robust_scale_mm = 4.0;
  int coarse_iterations = 8;          ///< updates at the coarse scale (not checked for convergence)
  double max_correspondence_mm = 10;  ///< reflected samples farther than this are ignored
  double inlier_threshold_mm = 1.5;   ///< |residual| below this counts as an inlier
  double landmark_weight = 1.0;       ///< weight of each landmark residual
  double convergence_deg = 1e-2;      ///< stop outer iterations when the normal turns less
  double convergence_mm = 1e-2;       ///< ... and the offset moves less than this
};

/// PlaneFitParams' fields, each declared once (ParamSpec), in the order a session writes them.
template <class Visit>
void for_each_field(Visit&& visit, PlaneFitParams& p) {
  visit(field("refine"), p.refine);
  visit(field("use_surface_symmetry"), p.use_surface_symmetry);
  visit(number("sample_count", "number of samples", 100, 100000), p.sample_count);
  visit(number("outer_iterations", "number of updates", 1, 50), p.outer_iterations);
  visit(length_mm("robust_scale_mm", "robust scale", 0.01, 50), p.robust_scale_mm);
  visit(length_mm("coarse_robust_scale_mm", "coarse robust scale", 0.01, 50),
        p.coarse_robust_scale_mm);
  visit(number("coarse_iterations", "number of coarse updates", 0, 50), p.coarse_iterations);
  visit(length_mm("max_correspondence_mm", "largest pairing distance", 0.1, 100),
        p.max_correspondence_mm);
  visit(length_mm("inlier_threshold_mm", "inlier threshold", 0.01, 50), p.inlier_threshold_mm);
  visit(number("landmark_weight", "landmarks' weight", 0, 1000), p.landmark_weight);
  visit(angle_deg("convergence_deg", "convergence angle", 0, 10), p.convergence_deg);
  visit(length_mm("convergence_mm", "convergence distance", 0, 10), p.convergence_mm);
}

struct PlaneFit {
  enum class Status { Converged, MaxIterations, Failed };
  Status status = Status::Failed;
  std::string message;           ///< plain words: how it ended, or why it failed
  Plane plane;                   ///< the refined plane (or the initial one without refining)
  Plane initial;                 ///< the starting plane
  std::string initial_method;    ///< "landmarks" or "automatic"
  double symmetry_rms_mm = 0.0;  ///< RMS of point-to-plane symmetry residuals over inliers
  double inlier_fraction = 0.0;  ///< fraction of samples whose residual is an inlier
  int iterations = 0;            ///< outer iterations (correspondence updates)
  int solver_iterations = 0;     ///< Ceres iterations summed over outer iterations
  std::string termination;       ///< Ceres termination of the last solve
  double seconds = 0.0;
  bool usable() const { return status != Status::Failed; }
};

/// Plane from nasion and orbit centres (required), plus optional midline points: the normal
/// runs from the left to the right orbit; with midline points the plane is the least-squares
/// fit to the midline points and the reflected-orbit condition.
Plane initial_plane_from_landmarks(const Landmarks& landmarks);

/// Plane found without landmarks, in any pose: 200 candidate normals spread over the half
/// sphere plus the principal axes and the coordinate axes, each through the centroid or up to
/// 6 mm beside it, scored by how far the mirrored surface lies from the original (80th
/// percentile of 300 probes' distances to the tangent planes of 30,000 samples); the best of
/// each of up to six basins (20° apart) is polished by a pattern search on tilt and offset (down
/// to 0.25° and 0.125 mm), and the best polished one wins.
Plane automatic_initial_plane(const SkullMesh& mesh);
/// The same from the mesh's vertex samples (all_vertex_samples) made beforehand.
Plane automatic_initial_plane(const SurfaceSamples& all);

/// How the automatic initial plane scores its candidates. Only the candidates up to the sixth
/// basin matter: every `first_pass_stride`-th spread normal (and the axes) is scored in full
/// first, and the first pass's sixth basin's score bounds the rest, which are given up as soon
/// as they are sure to score above it. The plane does not depend on the stride (1 scores every
/// candidate in full); only the time does.
struct InitialPlaneParams {
  int first_pass_stride = 4;
};
struct InitialPlaneResult {
  Plane plane;
  size_t candidates = 0;  ///< candidate normals scored
  size_t given_up = 0;    ///< candidates given up in the second pass
  /// Given-up candidates scored in full afterwards because the six basins of all candidates did
  /// not lie within the first pass's bound (so one of them could have opened a basin).
  size_t rescored = 0;
};
InitialPlaneResult automatic_initial_plane(const SurfaceSamples& all,
                                           const InitialPlaneParams& params);

/// Initial plane (landmarks when they hold the required three, otherwise automatic), then the
/// Ceres refinement. With `params.refine == false` returns the initial plane with its
/// symmetry measures.
/// `cloud`, when given, is the mesh's VertexCloud made beforehand (the same fit).
PlaneFit fit_sagittal_plane(const SkullMesh& mesh, const Landmarks& landmarks,
                            const PlaneFitParams& params = {}, const VertexCloud* cloud = nullptr);

}  // namespace cranioplan
