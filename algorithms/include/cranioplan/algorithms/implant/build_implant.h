#pragma once
// From markers to an implant: the paper's Delaunay 3D, and a closed fitted shell.
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "cranioplan/algorithms/implant/fixation_tabs.h"
#include "cranioplan/algorithms/implant/perforate.h"
#include "cranioplan/algorithms/implant/trim_to_bone.h"
#include "cranioplan/model/marker.h"
#include "cranioplan/model/material.h"
#include "cranioplan/model/mesh.h"
#include "cranioplan/model/param_spec.h"
#include "cranioplan/model/plane.h"

namespace cranioplan {

enum class ImplantMethod { Shell, Delaunay3D };
/// How the shell parametrises the defect: over the plane of the outer markers, or along rays
/// from a centre inside the skull (large and strongly curved defects).
enum class ImplantFrame { Radial, Planar };
const char* to_string(ImplantMethod m);

// The scalar fields' ranges, units and meanings are declared in for_each_field below.
struct ImplantParams {
  ImplantMethod method = ImplantMethod::Shell;
  // shell
  double resolution_mm = 1.0;  ///< target edge length of the shell
  /// Thickness when there are no inner markers; NaN: the bone thickness measured around the
  /// rim (6 mm when no skull is given).
  double thickness_mm = std::numeric_limits<double>::quiet_NaN();
  bool snap_rim_to_skull = true;  ///< rim points between edge markers are put onto the bone
  /// Surface markers are approximated rather than interpolated with this spline smoothing
  /// weight (dimensionless, ≥ 0; 0: the surfaces pass through them). Edge markers are always
  /// met exactly. Automatic plans use a little, to ride over noise in sampled bone.
  double surface_smoothing = 0.0;
  double max_rim_snap_mm = 3.0;  ///< rim points farther than this from bone stay where they are
  /// Fit to the bone: the shell is built this far beyond the rim (over the bone, mm), then the
  /// skull is subtracted (trim_to_bone.h), so the implant meets the defect's cut face all
  /// around and never enters the bone. Where no bone lies that far out (an oblique cut face,
  /// whose missing wedge the surface passes over first), up to three times as far; where there
  /// is none even then (an orbit), the rim stays at the edge markers. 0: off (the rims pass
  /// through the edge markers).
  double fit_to_bone_mm = 0.0;
  /// Fit to the bone: a rim point taken out to where the bone is first found, more than 0.5 mm
  /// off it and not yet across its surface, goes on while the bone comes nearer (the ray runs
  /// along a cut face past a corner or a burr hole of the opening) until it has crossed the
  /// surface, up to six times fit_to_bone_mm; false: it stays where the bone was first found
  /// (build_implant commands before version 11).
  bool fit_reaches_the_bone = true;
  /// Fit to the bone: when the fitted implant's edge stands off the bone by more than
  /// kRimGapTargetMm over an arc (rim_gap.h; with a clearance asked, further than it), the
  /// shell is built again 1 mm further over the bone, 1 mm less, 2 mm further, 2 mm less (1 to
  /// 10 mm), and the first fit whose edge meets the bone within that is kept; none: the one
  /// asked. The trim's voxels are coarse against ragged thin bone (an orbital roof, a sinus
  /// wall), where whether the rim's last piece of shell reaches a fragment or stops a
  /// millimetre short of it turns on the margin. false: the margin asked only (build_implant
  /// commands before version 13).
  bool fit_margin_search = true;
  /// Fitted to the bone, the shell is kept at least half a millimetre thicker than the fit's
  /// smallest feature (`trim.min_feature_mm`), so that the fit does not open away a thin part
  /// (a mirrored temporal squama of 1.5 mm) and leave a hole by the rim. false: the surfaces'
  /// own thickness, down to 0.3 mm (build_implant commands before version 14).
  bool fit_keeps_shell_thick = true;
  /// Where the scan ended across the opening (DefectRegion::scan_ends): the implant ends at
  /// these planes (their normals point out of the scanned volume), and its edge along them is
  /// not judged against bone, which beyond the scan is unknown. With the fit to the bone only.
  std::vector<Plane> scan_ends;
  TrimToBoneParams trim;  ///< how the shell is fitted to the bone (when fit_to_bone_mm > 0)
  /// What the implant is made of (none: the plan's surfaces as they are). A thickness of the
  /// material's replaces the inner surface (inner markers are not used); its under-contour sets
  /// the outer surface below the fitted one; its edge clearance is the fit to the bone's
  /// (`trim.clearance_mm`, when larger). A clearance or under-contour needs the fit to the bone.
  std::optional<Material> material;
  /// Stretches of the rim held further off the bone than the material's clearance (needs the
  /// fit to the bone).
  std::vector<ClearanceZone> clearance_zones;
  /// Holes drilled through the finished implant (perforate.h; the shell method only).
  PerforationParams perforations;
  /// Fixation tabs onto the outer table (fixation_tabs.h; the shell method with the skull; not
  /// with a plate laid on the bone, which is screwed through its own overlap). Added before the
  /// perforations, which keep off them.
  TabParams tabs;
  /// Radial needs a skull (its centroid is the centre) or `radial_center`; otherwise planar.
  ImplantFrame frame = ImplantFrame::Radial;
  std::optional<Eigen::Vector3d> radial_center;  ///< centre of the rays (inside the skull)
  // delaunay3d (VTK's vtkDelaunay3D parameters)
  double delaunay_alpha = 0.0;        ///< 0: convex hull; >0: alpha shape radius, mm
  double delaunay_tolerance = 0.001;  ///< point merge tolerance, fraction of the bounding box
  double delaunay_offset = 2.5;       ///< bounding triangulation size multiplier
};

/// ImplantParams' own scalar fields, each declared once (ParamSpec), in the order a session
/// writes them. Its trim, material, clearance zones, perforations and tabs declare theirs beside
/// their own structs.
template <class Visit>
void for_each_field(Visit&& visit, ImplantParams& p) {
  visit(length_mm("resolution_mm", "resolution", 0.2, 10)
            .with_option("resolution", "the shell's edge length"),
        p.resolution_mm);
  visit(length_mm("thickness_mm", "thickness", 0.1, 30)
            .unset_derived()
            .with_option("thickness",
                         "the implant's thickness where no inner markers are set (default: the "
                         "bone's, measured around the rim)"),
        p.thickness_mm);
  visit(field("snap_rim_to_skull"), p.snap_rim_to_skull);
  visit(number("surface_smoothing", "surface smoothing", 0, 1), p.surface_smoothing);
  visit(length_mm("max_rim_snap_mm", "largest rim snap", 0, 20), p.max_rim_snap_mm);
  visit(length_mm("fit_to_bone_mm", "fit to the bone", 0, 10)
            .with_option("fit-to-bone",
                         "build the shell this far over the bone and subtract the skull (0: off; "
                         "a clearance or under-contour needs it)"),
        p.fit_to_bone_mm);
  visit(length_mm("delaunay_alpha", "Delaunay alpha", 0, 1000)
            .with_option("alpha", "delaunay3d: the alpha shape's radius (0: the convex hull)"),
        p.delaunay_alpha);
  visit(number("delaunay_tolerance", "Delaunay tolerance", 0, 1)
            .with_option("tolerance",
                         "delaunay3d: points closer than this share of the bounding box merge"),
        p.delaunay_tolerance);
  visit(number("delaunay_offset", "Delaunay offset", 2.5, 100)
            .with_option("offset", "delaunay3d: the first triangulation's size, times the points'"),
        p.delaunay_offset);
}

struct ImplantResult {
  enum class Status { Built, TooFewMarkers, Failed };
  Status status = Status::Failed;
  std::string message;
  SkullMesh mesh;  ///< closed and outward-oriented for the shell method
  bool watertight = false;
  double thickness_used_mm = 0.0;    ///< shell without inner markers: the offset applied
  double rim_marker_error_mm = 0.0;  ///< largest distance from an edge marker to its rim
  int rim_points = 0;                ///< samples along each rim
  /// The margin the implant was fitted to the bone with (ImplantParams::fit_margin_search), mm;
  /// 0 when not fitted.
  double fit_to_bone_used_mm = 0.0;
  /// Why another margin than the one asked was used ("built 5 mm over the bone instead of 4: at
  /// 4 mm its edge stood 1.07 mm off the bone at (x, y, z) mm"), also in `message`; empty when
  /// the margin asked was used.
  std::string fit_margin_note;
  std::vector<Hole> holes;  ///< the perforations drilled
  std::vector<Tab> tabs;    ///< the fixation tabs added
  double seconds = 0.0;
  /// Where the time went, in the order it ran, s: "shell", "fit" (the whole fit to the bone)
  /// followed by its parts ("fit: opening", ...: TrimToBoneResult::stage_seconds), "tabs",
  /// "holes" (the stages the build ran).
  std::vector<std::pair<std::string, double>> stage_seconds;
  bool usable() const { return status == Status::Built; }
};
/// "built", "too_few_markers" or "failed": the word reports and `--json` give the status.
const char* status_name(ImplantResult::Status status);

/// Builds an implant from markers (types 0–3). `skull` is the original skull: the shell's rims
/// are snapped onto it and the default thickness is measured on it; may be null.
///
/// Shell: the outer and inner surfaces are thin-plate spline height fields, passing through
/// their markers, over a parametrisation of the defect (radial from the skull's centre by
/// default, or planar); both are sampled on rings that shrink from the rim (the edge markers in
/// angular order, densified to `resolution_mm`) to the centre, and a side wall joins the two
/// rims. The rim must be star-shaped around its centre in that parametrisation, which holds for
/// cranial defects seen from inside the skull.
ImplantResult build_implant(const std::vector<Marker>& markers, const SkullMesh* skull,
                            const ImplantParams& params = {});

class SurfaceLocator;
/// The same with the skull's locator built once by the caller: an interactive editor rebuilds
/// the implant on every marker edit, and building the locator of a 500k-triangle skull costs
/// more than the implant.
ImplantResult build_implant(const std::vector<Marker>& markers, const SkullMesh* skull,
                            const SurfaceLocator* skull_locator, const ImplantParams& params);

/// The parameters of a quick preview of the same implant, for the view while a marker is being
/// dragged: the same method, surfaces and thickness, without the fit to the bone and what needs
/// it (edge clearance, clearance zones, under-contour, onlay) or comes after it (tabs, holes).
/// It takes a small fraction of the fitted implant's time (docs/BENCHMARKS.md).
ImplantParams live_preview_params(ImplantParams params);

}  // namespace cranioplan
