#pragma once
// Perforations: holes through the implant for drainage and dura suspension, on a pattern of
// given spacing kept off the implant's edge, and single holes the user adds or takes away.
// Each is drilled along the implant's surface normal at its centre; the implant is meshed again
// from a field on a fine grid (the implant's signed distance, less the holes' cylinders), so it
// stays one closed, manifold surface.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "cranioplan/model/mesh.h"
#include "cranioplan/model/param_spec.h"

namespace cranioplan {

// The fields' ranges, units and meanings are declared in for_each_field below.
struct PerforationParams {
  bool pattern = false;
  double diameter_mm = 2.0;
  double spacing_mm = 10.0;
  double edge_distance_mm = 5.0;
  /// Pattern holes only where the implant is at least this thick plus 1 mm (the material's
  /// minimum thickness when built with one): the rim of a hole through thinner material is
  /// thinner still where the surface curves.
  double min_thickness_mm = 1.0;
  /// Single holes at these points (each moved onto the implant's surface); a pattern hole
  /// within half the spacing of one gives way to it.
  std::vector<Eigen::Vector3d> added;
  /// Pattern holes within half the spacing of these points are left out.
  std::vector<Eigen::Vector3d> removed;
  double voxel_mm = 0.2;      ///< at most a quarter of the diameter
  double max_voxels = 1.2e7;  ///< a large implant's grid is coarsened to this many voxels
  /// Field values within 1e-3 of the meshing's iso-level are moved that far off it (no sliver
  /// triangles); false: only a value exactly at it, as plans saved before this were meshed (set
  /// from the session command's version, not recorded).
  bool iso_gap = true;
  /// Each hole drilled along the plate's mid-normal (halfway between the outer surface's
  /// normal and the inner surface's under the hole) and below the inner surface under its
  /// whole footprint. Along the outer normal alone, a hole leaves a sloping inner surface
  /// obliquely, and its rim there is an acute wedge thinner than the material allows (the
  /// sample's PEEK plan: the inner surface 44° from the outer under one hole, a thin corner
  /// reaching 0.95 mm); a drill ending below the centre's inner surface leaves a floor at its
  /// deeper side. False: along the outer normal and 1 mm below the centre's inner surface, as
  /// plans saved before this were drilled (set from the session command's version, not
  /// recorded).
  bool mid_normal = true;
  /// A pattern hole whose rim leaves material thinner than `min_thickness_mm` reaching more
  /// than 0.8 mm out of the material thick enough (a corner the quality report refuses away
  /// from the bone: where a surface meets the hole's wall steeply slanted) is left out and the
  /// rest drilled again, up to three times; the message says how many. The user's holes are
  /// drilled as asked. False: every pattern hole drilled, as plans saved before build_implant
  /// 12 were (set from the session command's version, not recorded).
  bool sound_rims = true;
  bool any() const { return pattern || !added.empty(); }
};
/// PerforationParams' fields, each declared once (ParamSpec), in the order a session writes
/// them.
template <class Visit>
void for_each_field(Visit&& visit, PerforationParams& p) {
  visit(field("pattern").with_option(
            "perforate",
            "drill holes on a hexagonal pattern through the implant (drainage, dura suspension)"),
        p.pattern);
  visit(length_mm("diameter_mm", "diameter", 1, 6)
            .with_option("hole-diameter", "diameter of the holes"),
        p.diameter_mm);
  visit(length_mm("spacing_mm", "spacing", 4, 40)
            .with_option("hole-spacing", "between the pattern's holes"),
        p.spacing_mm);
  visit(length_mm("edge_distance_mm", "distance from the edge", 1, 20)
            .with_option("hole-edge-distance",
                         "the pattern's holes at least this far from the implant's edge"),
        p.edge_distance_mm);
  visit(length_mm("min_thickness_mm", "minimum thickness around them", 0.3, 10),
        p.min_thickness_mm);
  visit(length_mm("voxel_mm", "grid", 0.05, 1), p.voxel_mm);
  visit(number("max_voxels", "number of grid voxels", 1e5, 5e7), p.max_voxels);
  visit(field("added"), p.added);
  visit(field("removed"), p.removed);
}
/// Why the parameters cannot be used (a value out of its range), or empty.
std::string perforation_problem(const PerforationParams& p);

/// A hole: its centre on the outer surface and the direction it is drilled (outward, unit).
struct Hole {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  bool added = false;  ///< one of PerforationParams::added (else the pattern's)
};

struct PerforateResult {
  enum class Status { Drilled, Failed };
  Status status = Status::Failed;
  std::string message;
  SkullMesh mesh;  ///< the implant with its holes (the input, untouched, when Failed)
  std::vector<Hole> holes;
  double seconds = 0.0;
  bool usable() const { return status == Status::Drilled; }
};

/// Drills the holes into `implant` (closed, outward-oriented). `inside`: a point inside the
/// skull, which tells the implant's outer surface (facing away from it) from its inner one.
PerforateResult perforate(const SkullMesh& implant, const Eigen::Vector3d& inside,
                          const PerforationParams& params);
/// The same with the drilled implant meshed in `into` (the implant as it came when nothing is
/// drilled; the result's own mesh stays empty). `into` must not be `implant`.
PerforateResult perforate(const SkullMesh& implant, const Eigen::Vector3d& inside,
                          const PerforationParams& params, SkullMesh& into);

/// Whether a hole goes through `implant` (located by `locator`): its axis line, 15 mm to either
/// side of its centre, meets no surface (a plate is at most 15 mm thick).
bool hole_goes_through(const class SurfaceLocator& locator, const Hole& hole);

}  // namespace cranioplan
