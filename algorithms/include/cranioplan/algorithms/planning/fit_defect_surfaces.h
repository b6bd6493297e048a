#pragma once
// The outer and inner surfaces of the missing bone, fitted to the intact bone all around a
// detected opening. Rays from inside the skull (the detection's centre) sample the outer and
// inner table on a wide ring of intact bone. The outer surface is a radius field r(d) over the
// ray directions d, a thin-plate spline with a quadratic trend (so the curvature of the
// surroundings carries across the opening); the inner one lies a thickness field t(d) below it
// (a spline with an affine trend: fitting the inner radius on its own lets the two surfaces'
// trends drift apart across a wide opening).
//
// Mirror-guided: the registered mirror gives a first guess of both radii inside the opening;
// the splines then fit only the mirror's mismatch with the original skull on the ring (smooth
// correction fields), so the healthy side's shape is kept but bent to meet the bone around the
// defect. Rim-only (the mirror does not cover the opening): the radii themselves are fitted.
//
// Rays that pass within `rim_clearance_mm` of the opening are not used: at a cut face that is
// not along the rays they graze the bone and see neither table where it would continue.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cranioplan/algorithms/geometry/thin_plate_spline.h"
#include "cranioplan/algorithms/planning/detect_defect.h"

namespace cranioplan {

class PointIndex;
class SurfaceLocator;

struct DefectSurfaceParams {
  double ring_width_mm = 25.0;    ///< width of the intact ring the surfaces are fitted to, mm
  double rim_clearance_mm = 3.0;  ///< rays nearer the opening are not used, mm (≥ 0)
  /// Rays whose entry and exit surfaces are further from parallel than this are not used, deg:
  /// near an oblique cut face a ray enters or leaves through the cut instead of a table, and
  /// its thickness is too small (0: off).
  double max_table_angle_deg = 30.0;
  /// Rays that leave the bone through a surface tilted more than this from the ray are not
  /// used at all, deg: they left through a cut face, below the outer table (0: off).
  double max_outer_tilt_deg = 50.0;
  double ray_spacing_mm = 2.0;   ///< between sampled rays at the rim's radius, mm (0.5..10)
  double site_spacing_mm = 4.0;  ///< fitting sites on the ring at least this far apart, mm
  /// Spline smoothing weight per site (dimensionless, ≥ 0) of the thickness and of the
  /// mirror's corrections: fields that vary gently, so it rides over the bone's roughness.
  double smoothing = 0.03;
  /// The same for the outer radius itself (rim-only): the shape of the surroundings is the
  /// only guide across the opening, and smoothing it as much as the corrections flattens the
  /// vault: the middle of an opening comes out low (docs/AUTOPLAN.md, "Rim-only").
  double outer_smoothing = 0.003;
  /// Rim-only: the outer radius as it is, with the spline's quadratic trend (Quadratic), or as
  /// its excess over the sphere fitted to the ring (Sphere); Best: whichever predicts the
  /// ring's band next to the opening better from the rest of the ring.
  enum class Vault { Best, Quadratic, Sphere };
  Vault vault = Vault::Best;
  /// Sites whose residual after a first fit exceeds this many robust standard deviations
  /// (and 1 mm) are dropped before the final fit: foramina, sutures, cut-face fragments.
  double outlier_sigmas = 3.0;
  /// Mirror-guided, the mirror is read over a footprint of this radius at the rim's radius, mm
  /// (0..10; 0: along the one ray): the ray and six around it, their outer radii and thicknesses
  /// averaged, none where fewer than four pass through both of its tables. Read along one
  /// ray, the mirror's surfaces jump wherever its bone does (a brow ridge, a sinus wall, a
  /// ray through bone just thicker than `max_thickness_mm`), and which markers land on such a
  /// ray changes with where the rays start. 3 mm, half the 6 mm between surface markers: each
  /// marker reads the mirror over the stretch it stands for, and features of the mirror
  /// narrower than the markers' spacing do not alias into the implant.
  double mirror_footprint_mm = 3.0;
  /// Mirror-guided, a fitting site that averages fewer of the ring's rays than the ring's
  /// median site is smoothed in proportion (`smoothing` × median / its rays): a mean of fewer
  /// rays is less certain. Such sites lie where the ring is cut short (its edges, rays left out
  /// around an orbit), which rays fall in them changes with where the rays start, and weighed
  /// like full sites they bent the mirror's correction there (the sample's plan moved to Dice
  /// 0.911 against its own under 1 mm moves of the rays; 0.938 weighed). Rim-only fits weigh
  /// every site alike (on SkullFix weighing moved each case's Dice by at most 0.0015, the median
  /// 0.9253 to 0.9240). False: as propose_markers 5 and older fitted them.
  bool weigh_sites_by_rays = true;
};

/// A sphere fitted to the vault around an opening.
struct VaultSphere {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double radius = 0.0;
  /// Distance from `from` (inside the sphere) along unit `dir` to the sphere.
  double radius_along(const Eigen::Vector3d& from, const Eigen::Vector3d& dir) const;
};

class DefectSurfaces {
 public:
  enum class Status { Fitted, Failed };
  Status status = Status::Failed;
  std::string message;
  bool mirror_guided = false;
  int ring_rays = 0;  ///< intact rays on the ring (both tables met)
  int sites = 0;      ///< fitting sites used (after thinning and outliers)
  /// RMS residual of the fit over the ring's rays within the outlier limit, outer table (over
  /// all the rays, a few rays past an orbit, 30-50 mm off, would dominate it).
  double outer_rms_mm = 0.0;
  double thickness_rms_mm = 0.0;  ///< the same, bone thickness (rays through both tables)
  /// Rays off the fit by more than the outlier limit (`outlier_sigmas` robust σ, at least 1 mm):
  /// bone the fitted surface does not describe (an orbital roof, a fragment of a cut face).
  int outer_off_rays = 0;
  int thickness_off_rays = 0;
  double outer_off_limit_mm = 0.0;      ///< that limit, outer table
  double thickness_off_limit_mm = 0.0;  ///< that limit, thickness
  /// Rim-only: the sphere the outer surface was fitted beyond, when the ring preferred it to
  /// the spline's quadratic trend alone.
  const std::optional<VaultSphere>& vault() const { return vault_; }
  /// The ring's bone: outer and inner table points of the intact rays (both tables met) and
  /// each ray's distance from the opening, mm.
  std::vector<Eigen::Vector3d> ring_outer, ring_inner;
  std::vector<double> ring_distance_mm;
  /// For each ring ray, how squarely its first bone faces it: the cosine between the ray and
  /// the inward normal there (1: the inner table met square on; near 0: a cut face met
  /// side-on, above where the inner table would go on).
  std::vector<double> ring_inner_facing;

  bool fitted() const { return status == Status::Fitted; }
  /// The fitted outer and inner surface points along the ray from the centre in direction
  /// `dir` (unit); none when the direction is outside the fitted cap or, mirror-guided, the
  /// mirror has no bone there.
  std::optional<std::pair<Eigen::Vector3d, Eigen::Vector3d>> at(const Eigen::Vector3d& dir) const;

  /// From now on at() gives these surfaces' radii averaged with `other`'s (fitted to the same
  /// opening, so from the same centre), `weight` of `other`'s (0..1), along each ray where both
  /// have a value; these alone where `other` has none. Two fits guided by different priors
  /// (a shape model and the ring, say) err differently, and their mean errs less than either.
  /// Where `other` has no value along some of `directions` (the opening's rays; a model whose
  /// template stops inside the opening), its weight fades to 0 over `taper_mm` (at the
  /// surface's radius, smoothly) towards them instead of stopping with a step (0: a step).
  void blend_with(std::shared_ptr<const DefectSurfaces> other, double weight,
                  const std::vector<Eigen::Vector3d>& directions = {}, double taper_mm = 10.0);
  /// How much of blend_with()'s weight at() gives `other`'s surfaces along unit `dir` (0..1: 1
  /// where it weighs fully, 0 where it has no value or none was given).
  double blend_share(const Eigen::Vector3d& dir) const;

 private:
  friend struct DefectSurfaceFit;  // the fit's stages (fit_defect_surfaces.cpp)
  Eigen::Vector2d uv(const Eigen::Vector3d& dir) const;
  /// The mirror's outer radius and thickness along `dir` over the footprint; none where it has
  /// too little bone there.
  std::optional<std::pair<double, double>> mirror_along(const Eigen::Vector3d& dir) const;
  /// The outer radius and the thickness along unit `dir` (no blend), none outside the cap.
  std::optional<std::pair<double, double>> radii(const Eigen::Vector3d& dir) const;
  /// The share of blend_with()'s weight along unit `dir` at outer radius `r_out`: 1 at least
  /// the taper's width from where `other` has no value, fading to 0 there.
  double blend_taper(const Eigen::Vector3d& dir, double r_out) const;
  std::shared_ptr<const DefectSurfaces> blend_;
  double blend_weight_ = 0.0;
  std::shared_ptr<const PointIndex> blend_gaps_;  // directions where `blend_` has no value
  double blend_taper_mm_ = 0.0;
  Eigen::Vector3d center_ = Eigen::Vector3d::Zero(), axis_ = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d e1_ = Eigen::Vector3d::UnitX(), e2_ = Eigen::Vector3d::UnitY();
  double scale_ = 1.0;                      // mm per unit of the gnomonic projection
  double max_cos_ = 0.0;                    // cosine of the cap's half-angle
  const SurfaceLocator* mirror_ = nullptr;  // prior (not owned); null: rim-only
  double max_thickness_mm_ = 20.0;          // DetectDefectParams' default
  double mirror_footprint_mm_ = 0.0;
  ThinPlateSpline outer_, thickness_;
  std::optional<VaultSphere> vault_;  // set: outer_ fits the radius beyond this sphere
};

/// Fits the surfaces of `defect` (found by detect_defect on the skull that `bone` locates).
/// `mirror`: the registered mirrored skull, or null for rim-only fitting; it must outlive the
/// result. `detect` gives the plausible bone thickness of a ray.
DefectSurfaces fit_defect_surfaces(const DefectRegion& defect, const SurfaceLocator& bone,
                                   const SurfaceLocator* mirror,
                                   const DefectSurfaceParams& params = {},
                                   const DetectDefectParams& detect = {});

}  // namespace cranioplan
