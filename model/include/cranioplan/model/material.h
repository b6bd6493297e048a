#pragma once
// What the implant is made of, and how its edge is finished for that material: the parameters a
// manufacturer's design rules give (thickness, the thinnest printable wall, the gap left to the
// bone's cut edge, how far the outer surface is set below the skull's), and the density for the
// implant's mass. Presets for PEEK, PMMA and a titanium plate; any other as a custom material.
#include <Eigen/Core>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "cranioplan/model/param_spec.h"

namespace cranioplan {

// The fields' ranges, units and meanings are declared in for_each_field below.
struct Material {
  std::string id = "custom";    ///< preset id ("peek", "pmma", "titanium") or "custom"
  std::string name = "custom";  ///< as shown and printed ("PEEK", …)
  /// NaN: the implant follows the bone (the inner surface of the plan, from the inner markers or
  /// the bone's thickness around the rim).
  double thickness_mm = std::numeric_limits<double>::quiet_NaN();
  double min_thickness_mm = 1.0;
  double edge_clearance_mm = 0.0;
  double under_contour_mm = 0.0;
  double density_g_cm3 = 1.0;
  /// A plate laid on the bone (onlay): it covers the opening at the skull's outer surface and
  /// reaches this far beyond the rim over the outer table (needs a thickness, and no clearance
  /// or under-contour). 0: the implant fills the opening (inlay).
  double onlay_mm = 0.0;
};

/// Material's fields, each declared once (ParamSpec), in the order a session writes them.
template <class Visit>
void for_each_field(Visit&& visit, Material& m) {
  visit(field("id"), m.id);
  visit(field("name"), m.name);
  visit(length_mm("thickness_mm", "thickness", 0.3, 15)
            .with_option("plate-thickness", "a plate of this thickness instead of the bone's")
            .unset_derived(),
        m.thickness_mm);
  visit(
      length_mm("min_thickness_mm", "minimum thickness", 0.3, 10)
          .with_option("min-thickness", "the material's thinnest wall (thinner is not printable)"),
      m.min_thickness_mm);
  visit(length_mm("edge_clearance_mm", "edge clearance", 0, 3)
            .with_option("clearance", "gap between the implant's edge and the bone's cut edge"),
        m.edge_clearance_mm);
  visit(length_mm("under_contour_mm", "under-contour", 0, 1)
            .with_option("under-contour", "outer surface set this far below the skull's"),
        m.under_contour_mm);
  visit(ParamSpec{"density_g_cm3", "density", 0.1, 25, "g/cm³"}.with_option("density",
                                                                            "for the mass"),
        m.density_g_cm3);
  visit(length_mm("onlay_mm", "onlay's overlap", 3, 20).zero_for_none(), m.onlay_mm);
}

/// The presets, in the order a user is offered them: PEEK, PMMA, titanium plate.
const std::vector<Material>& material_presets();
/// The preset of that id or name (case does not matter); none for another word.
std::optional<Material> material_preset(const std::string& id_or_name);
/// Why the material cannot be used (a value out of its range), or empty.
std::string material_problem(const Material& m);
/// "PEEK (follows the bone, min 2.0 mm, clearance 1.0 mm, under-contour 0.0 mm, 1.30 g/cm³)".
std::string describe(const Material& m);

/// A stretch of the rim with its own edge clearance (e.g. 3 mm along the temporal bone, where
/// the temporalis muscle is laid back over the implant): the implant's edge keeps `clearance_mm`
/// off the bone wherever the bone it faces lies within `radius_mm` of `center`.
struct ClearanceZone {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  ///< a point on the rim, mm
  double radius_mm = 15.0;
  double clearance_mm = 3.0;
};
/// ClearanceZone's fields, each declared once (ParamSpec), in the order a session writes them.
template <class Visit>
void for_each_field(Visit&& visit, ClearanceZone& z) {
  visit(field("center"), z.center);
  visit(length_mm("radius_mm", "zone's radius", 1, 100), z.radius_mm);
  visit(length_mm("clearance_mm", "zone's clearance", 0, 3), z.clearance_mm);
}
/// Why the zone cannot be used, or empty.
std::string zone_problem(const ClearanceZone& z);
/// A zone's clearance blends into the one around it over this distance beyond its radius, mm:
/// a step would ask two clearances of the same stretch of edge, whose points face bone on both
/// sides of it.
constexpr double kZoneBlendMm = 8.0;
/// The clearance asked facing the bone point `p`: the largest of `base_mm` and the zones' (each
/// its own within its radius, blending into `base_mm` over kZoneBlendMm beyond).
double clearance_at(const Eigen::Vector3d& p, double base_mm,
                    const std::vector<ClearanceZone>& zones);

}  // namespace cranioplan
