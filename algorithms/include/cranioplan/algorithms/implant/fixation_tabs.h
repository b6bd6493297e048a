#pragma once
// Fixation tabs: strips of the implant's material that reach beyond its edge onto the skull's
// outer table, following the bone, each with one or two countersunk screw holes. They are
// placed evenly along the rim (away from thin bone and from the midline's sinus) or where the
// user puts them, and joined to the implant as one solid: the implant's signed distance and the
// tabs' (a layer over the bone and the implant, inside each tab's outline) are combined on a
// fine grid, the screw holes subtracted, and the result meshed again.
#include <Eigen/Core>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "cranioplan/algorithms/implant/perforate.h"
#include "cranioplan/model/mesh.h"
#include "cranioplan/model/param_spec.h"
#include "cranioplan/model/plane.h"

namespace cranioplan {

class SurfaceLocator;

// The fields' ranges, units and meanings are declared in for_each_field below.
struct TabParams {
  /// Tabs placed evenly along the rim (with `count`), unless `positions` are given.
  bool automatic = false;
  int count = 0;  ///< 0: one per 40 mm of rim (3 to 8)
  /// A tab at the rim point nearest each of these points (the user's tabs); when given, the
  /// even placement is not used.
  std::vector<Eigen::Vector3d> positions;
  double length_mm = 9.0;
  /// NaN: the countersink (or hole) with a ring of the material's minimum thickness plus 0.5 mm
  /// on either side, at least 6 mm. Its far end is round.
  double width_mm = std::numeric_limits<double>::quiet_NaN();
  /// NaN: the material's minimum thickness under the countersink plus 0.4 mm, at least 1.5 mm
  /// (without a material, a minimum of 1 mm).
  double thickness_mm = std::numeric_limits<double>::quiet_NaN();
  int screws = 1;                        ///< two lie along the tab
  double screw_diameter_mm = 1.8;        ///< the hole for the screw's shank
  double countersink_diameter_mm = 3.0;  ///< 90°; 0: none, else wider than the hole
  double midline_distance_mm = 10.0;     ///< used with `midline`
  std::optional<Plane> midline;          ///< the plan's midsagittal plane
  double min_bone_mm = 2.0;
  double voxel_mm = 0.2;
  double max_voxels = 1.2e7;  ///< a large implant's grid is coarsened to this many voxels
  /// Field values within 1e-3 of the meshing's iso-level are moved that far off it (no sliver
  /// triangles); false: only a value exactly at it, as plans saved before this were meshed (set
  /// from the session command's version, not recorded).
  bool iso_gap = true;
  /// Over the implant a tab's underside lies on the implant's outer surface, however far below
  /// the bone's outer table that is (at most the tab's thickness where it leaves the edge: the
  /// placement refuses a larger step). False: nowhere deeper than 1.5 mm below the outer table
  /// at the edge, which left a gap and a thin overhang over an implant lower than that, as
  /// plans saved before build_implant 9 were made (set from the session command's version, not
  /// recorded).
  bool follow_implant = true;
  /// Where the implant is the outermost surface under a tab, the underside comes down onto it
  /// from the bridging of narrow gaps (at most 0.3 mm deep within 0.6 mm of the highest point)
  /// where it lies up to 1 mm below, not where 2 mm or more (its wall, dropping into the gap at
  /// the edge), part of the way between. False: the bridging applies over the implant too,
  /// which held a tab up to 1 mm over a rounded edge with air under it (thin material away
  /// from the bone), as plans saved before build_implant 10 were made (set from the session
  /// command's version, not recorded).
  bool on_implant_edge = true;
  /// The even placement measures how each tab rests on the bone as the quality report does
  /// (tab_gap) and places again, away from there, a tab that stands more than 0.2 mm off it
  /// (over uneven fragments, or a step down beyond the implant's edge), up to three times.
  /// False: placed once, as plans saved before build_implant 12 were made (set from the
  /// session command's version, not recorded).
  bool keep_on_bone = true;
  bool any() const { return automatic || !positions.empty(); }
};
/// TabParams' fields, each declared once (ParamSpec), in the order a session writes them.
template <class Visit>
void for_each_field(Visit&& visit, TabParams& p) {
  visit(field("automatic")
            .with_option("tabs",
                         "fixation tabs onto the outer table, evenly along the rim "
                         "(away from thin bone and the midline)"),
        p.automatic);
  visit(number("count", "count", 0, 12)
            .with_option("tab-count", "how many tabs (0: one per 40 mm of rim)"),
        p.count);
  visit(field("positions"), p.positions);
  visit(length_mm("length_mm", "length", 4, 25)
            .with_option("tab-length", "beyond the implant's edge"),
        p.length_mm);
  visit(length_mm("width_mm", "width", 3, 15)
            .with_option("tab-width",
                         "of the tabs; default: the countersink with a ring of the material's "
                         "minimum thickness + 0.5 mm, at least 6")
            .unset_derived(),
        p.width_mm);
  visit(length_mm("thickness_mm", "thickness", 0.5, 5)
            .with_option("tab-thickness",
                         "of the tabs; default: the material's minimum under the countersink "
                         "+ 0.4 mm, at least 1.5")
            .unset_derived(),
        p.thickness_mm);
  visit(number("screws", "number of screws", 1, 2)
            .with_option("tab-screws", "screws per tab (1 or 2, along the tab)"),
        p.screws);
  visit(length_mm("screw_diameter_mm", "screw holes' diameter", 1, 3)
            .with_option("screw-diameter", "the screw holes'"),
        p.screw_diameter_mm);
  visit(
      length_mm("countersink_diameter_mm", "countersinks' diameter", 1.2, 8)
          .with_option("countersink", "the countersinks' diameter at the tab's top, 90° (0: none)")
          .zero_for_none(),
      p.countersink_diameter_mm);
  visit(length_mm("midline_distance_mm", "distance from the midline", 0, 40)
            .with_option("tab-midline-distance",
                         "tabs at least this far from the midsagittal plane (the sagittal sinus)"),
        p.midline_distance_mm);
  visit(field("midline"), p.midline);
  visit(length_mm("min_bone_mm", "bone thickness under the screws", 0, 10)
            .with_option("tab-min-bone", "screws only into bone at least this thick"),
        p.min_bone_mm);
  visit(length_mm("voxel_mm", "grid", 0.05, 1), p.voxel_mm);
  visit(number("max_voxels", "number of grid voxels", 1e5, 5e7), p.max_voxels);
}
/// Why the parameters cannot be used (a value out of its range), or empty.
std::string tab_problem(const TabParams& p);

/// The parameters with the width and thickness set (those left NaN derived from the material's
/// minimum thickness, `material_min_thickness_mm`, NaN without a material).
TabParams resolved(const TabParams& p, double material_min_thickness_mm);

/// A tab as placed: its frame at the implant's edge and its screws.
struct Tab {
  Eigen::Vector3d rim = Eigen::Vector3d::Zero();       ///< where it leaves the implant's edge
  Eigen::Vector3d outward = Eigen::Vector3d::UnitX();  ///< along the tab, away from the implant
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();   ///< the bone's outer normal under it
  double length_mm = 0.0, width_mm = 0.0, thickness_mm = 0.0;
  std::vector<Hole> screws;  ///< each hole's centre on the tab's top, drilled along `normal`
  double bone_mm = 0.0;      ///< the thinnest bone under its screws, mm
  double midline_mm = std::numeric_limits<double>::quiet_NaN();  ///< nearest to the midline
  bool added = false;  ///< placed by the user (TabParams::positions)
};

struct TabResult {
  enum class Status { Added, Failed };
  Status status = Status::Failed;
  std::string message;
  SkullMesh mesh;  ///< the implant with its tabs (the input, untouched, when Failed)
  std::vector<Tab> tabs;
  double rim_length_mm = 0.0;  ///< of the implant's edge, along which the tabs are placed
  double seconds = 0.0;
  bool usable() const { return status == Status::Added; }
};

/// Adds tabs to `implant` (closed, outward-oriented) fitted onto the skull located by `bone`
/// (the bone as a solid). `inside`: a point inside the skull. `params` with the width and
/// thickness set (resolved()).
TabResult add_fixation_tabs(const SkullMesh& implant, const SurfaceLocator& bone,
                            const Eigen::Vector3d& inside, const TabParams& params);
/// The same with the implant and its tabs meshed in `into` (the implant as it came when the
/// tabs cannot be added; the result's own mesh stays empty): a mesh cannot be moved, only
/// copied. `into` must not be `implant`.
TabResult add_fixation_tabs(const SkullMesh& implant, const SurfaceLocator& bone,
                            const Eigen::Vector3d& inside, const TabParams& params,
                            SkullMesh& into);

/// How far a tab stands off the bone, mm: over the part of it that lies on the bone's outer
/// table (beyond its edge's groove, away from the screw holes, sampled every 0.25 mm), the
/// largest of the gaps between its underside and the bone, each point taking the smallest gap
/// within 0.6 mm of it (the underside bridges cracks narrower than twice that and rests on the
/// bone beside them); negative where the tab enters the bone. `implant` (with the tab) is
/// located by `self`.
double tab_gap(const SurfaceLocator& self, const SurfaceLocator& bone, const Tab& tab);

}  // namespace cranioplan
