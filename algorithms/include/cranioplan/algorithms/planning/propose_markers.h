#pragma once
// Marker proposal for a detected defect. The outer and inner surfaces of the missing bone are
// fitted to the intact bone around the opening (fit_defect_surfaces.h) — guided by the
// registered mirror where it covers the opening, from the ring alone otherwise — and sampled
// as markers: outer edge markers along the rim, surface markers over the opening (smoothed with
// the paper's smoother and put back onto the fitted surfaces), and support markers on the
// intact bone next to the rim. The wizard's "Propose markers" and the automatic planner both
// use it.
#include <string>
#include <vector>

#include "cranioplan/algorithms/alignment/register_icp.h"
#include "cranioplan/algorithms/implant/smooth_markers.h"
#include "cranioplan/algorithms/planning/detect_defect.h"
#include "cranioplan/algorithms/planning/fit_defect_surfaces.h"
#include "cranioplan/model/marker.h"
#include "cranioplan/model/plane.h"

namespace cranioplan {

class SurfaceLocator;

/// How the missing bone's surfaces are guided: the registered mirror, the ring alone, or a shape
/// model of the normal skull fitted to the intact bone (shape_prior.h).
enum class PlanMethod { Auto, Mirror, RimOnly, ShapeModel };
const char* to_string(PlanMethod m);
/// "auto", "mirror", "rim-only" or "model"; false for anything else.
bool plan_method_from_string(const std::string& text, PlanMethod& out);

struct ProposeParams {
  DetectDefectParams detect;
  /// Auto: the mirror where it covers the defect; elsewhere the shape model when one is given
  /// and fits, else the ring. ShapeModel: the model averaged into the mirror's surfaces (where
  /// it covers) or the ring's.
  PlanMethod method = PlanMethod::Auto;
  double min_mirror_coverage = 0.8;  ///< Auto uses the mirror above this coverage, 0..1
  /// Guided by a shape model, the model's surfaces are averaged into the mirror's (where it
  /// covers the opening) or the ring's, this much of the model's (0..1; 1: the model alone
  /// wherever it reaches).
  double shape_model_weight = 0.5;
  double edge_spacing_mm = 4.0;     ///< proposed edge markers along the rim, mm (>0)
  double surface_spacing_mm = 6.0;  ///< proposed surface and support markers, mm (>0)
  /// Inner support markers only where the ring ray's first bone faces it within this angle
  /// (the inner table), deg (0..90; 90: every ray). Beside an oblique cut face a ray from the
  /// centre first meets the face, above where the inner table would go on, and a marker there
  /// lifts the implant's inner surface off the missing wedge of bone.
  double max_support_inner_tilt_deg = 45.0;
  /// Support markers lie on the ring's bone only where the fitted surface describes it: bone
  /// further than this from the fitted table along its ray is not where the table goes on (a
  /// fragment below a sinus, an orbital roof, bone across the opening), mm (0: off).
  double max_support_off_fit_mm = 1.5;
  /// Inner support markers only where the ring's bone is at most this many times its median
  /// thickness (plus 1 mm): a ray through much more bone met the inner table where it turns
  /// into other bone (the floor of a fossa below a flap's lower edge, a sinus's walls), and a
  /// marker there pulls the implant's inner surface down to it (0: no limit).
  double max_support_layers = 2.0;
  SmoothParams smooth{10.0, 2.0, 1};  ///< applied to surface markers (put back after)
  DefectSurfaceParams surfaces;       ///< fitting the surfaces to the intact ring
};

/// Which sources shaped the missing bone's surfaces: shares of the opening's rays (0..1) whose
/// outer and inner surface came from the mirror (bent to meet the ring), from the ring alone,
/// and of those, the shape model's weight averaged over the rays (`with_model`: 1 where it
/// weighs fully, less where its weight fades). The edge markers lie on these surfaces along the
/// rim; the support markers on the skull's own bone.
struct SurfaceSources {
  double mirror = 0.0;      ///< the registered mirror, corrected to the ring
  double ring = 0.0;        ///< the fit to the intact ring alone
  double with_model = 0.0;  ///< of the two, the shape model's share (its weight's fraction)
  double none = 0.0;        ///< no surface (outside the fitted cap, no mirrored bone)
  /// "the opening's surfaces: 64% mirror with the shape model, 36% mirror alone; edge markers on
  /// them along the rim, support markers on the skull's own bone"
  std::string describe() const;
};

struct MarkerProposal {
  enum class Status { Proposed, NoDefect, Failed };  ///< Failed: the surfaces could not be fitted
  Status status = Status::NoDefect;
  std::string message;
  DefectRegion defect;
  PlanMethod method_used = PlanMethod::RimOnly;
  double mirror_coverage = 0.0;  ///< fraction of the opening's rays that meet mirrored bone
  std::string surfaces_message;  ///< how the surfaces were fitted (ring rays, residual)
  double ring_rms_mm = 0.0;      ///< DefectSurfaces::outer_rms_mm: the outer fit's residual
  SurfaceSources sources;        ///< which sources shaped the surfaces over the opening
  std::vector<Marker> markers;   ///< ids from `first_id` on
  bool proposed() const { return status == Status::Proposed; }
};

/// How the surfaces were found, for messages: "mirror-guided (mirror covers 97% of the opening)"
/// or "rim-only fitting (…)".
std::string describe_method(PlanMethod method, double mirror_coverage);

/// The share of the opening's rays that meet the registered mirror's bone (both tables).
double mirror_coverage(const DefectRegion& defect, const SurfaceLocator& mirror,
                       const ProposeParams& params);

/// The defect seen from inside the cavity, on the midsagittal plane: from the vault's centre
/// (vault_center) moved towards the opening seen from there until it is seen 50° wide (at most
/// half the vault's radius), or from the skull's surface centroid (surface_centroid) when the
/// opening is seen that wide from the vault's centre already; from DetectDefectParams::center when
/// set.
DefectRegion detect_defect_near_plane(const SkullMesh& skull, const SurfaceLocator& bone,
                                      const Plane& plane, const DetectDefectParams& params);

/// The region for registering the mirror locally: a sphere around the opening's rim reaching
/// `margin_mm` beyond it.
RegionOfInterest local_registration_region(const DefectRegion& defect, double margin_mm);

/// Markers for an already detected defect; `bone` locates the skull it was found in, `mirror`
/// the registered mirrored skull, `model` (may be null) a shape model fitted to the skull
/// (ShapePrior::locator).
MarkerProposal propose_markers_for_defect(const DefectRegion& defect, const SurfaceLocator& bone,
                                          const SurfaceLocator& mirror, const ProposeParams& params,
                                          int first_id = 1, const SurfaceLocator* model = nullptr);

/// Detects the defect, then proposes markers (status NoDefect when there is none).
MarkerProposal propose_markers(const SkullMesh& skull, const SurfaceLocator& bone,
                               const Plane& plane, const SurfaceLocator& mirror,
                               const ProposeParams& params, int first_id = 1);

}  // namespace cranioplan
