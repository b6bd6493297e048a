#include "cranioplan/model/material.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>

namespace cranioplan {

namespace {

Material preset(const char* id, const char* name, double thickness, double min_thickness,
                double clearance, double under_contour, double density, double onlay = 0.0) {
  Material m;
  m.onlay_mm = onlay;
  m.id = id;
  m.name = name;
  m.thickness_mm = thickness;
  m.min_thickness_mm = min_thickness;
  m.edge_clearance_mm = clearance;
  m.under_contour_mm = under_contour;
  m.density_g_cm3 = density;
  return m;
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

const std::vector<Material>& material_presets() {
  constexpr double kBone = std::numeric_limits<double>::quiet_NaN();
  static const std::vector<Material> presets = {
      // Milled or printed PEEK: full thickness, a 1 mm gap at the edge for the fit in theatre.
      preset("peek", "PEEK", kBone, 2.0, 1.0, 0.0, 1.30),
      // PMMA (cast or printed): brittle, so no thin walls; set a little below the scalp.
      preset("pmma", "PMMA", kBone, 2.0, 1.0, 0.5, 1.18),
      // A titanium (Ti-6Al-4V) plate on the outer table, overlapping the rim by 8 mm.
      preset("titanium", "titanium plate", 1.0, 0.6, 0.0, 0.0, 4.43, 8.0),
  };
  return presets;
}

std::optional<Material> material_preset(const std::string& id_or_name) {
  const std::string want = lower(id_or_name);
  for (const Material& m : material_presets())
    if (want == m.id || want == lower(m.name)) return m;
  return std::nullopt;
}

std::string material_problem(const Material& m) {
  if (std::string problem = range_problems("the", m); !problem.empty()) return problem;
  const ParamSpec thickness = spec_of<Material>("thickness_mm");
  if (!std::isnan(m.thickness_mm) && m.thickness_mm < m.min_thickness_mm)
    return thickness.problem("the", m.thickness_mm, m.min_thickness_mm, thickness.max) +
           " (not below the minimum thickness)";
  if (m.onlay_mm != 0.0) {
    if (std::isnan(m.thickness_mm)) return "a plate laid on the bone needs a thickness";
    if (m.edge_clearance_mm > 0.0 || m.under_contour_mm > 0.0)
      return "a plate laid on the bone has no edge clearance or under-contour";
  }
  if (m.name.empty()) return "the material has no name";
  return {};
}

std::string describe(const Material& m) {
  char buf[240];
  char thickness[80];
  if (m.onlay_mm > 0.0)
    std::snprintf(thickness, sizeof(thickness), "a %.1f mm plate on the bone, %.0f mm over the rim",
                  m.thickness_mm, m.onlay_mm);
  else if (std::isnan(m.thickness_mm))
    std::snprintf(thickness, sizeof(thickness), "follows the bone");
  else
    std::snprintf(thickness, sizeof(thickness), "%.1f mm thick", m.thickness_mm);
  std::snprintf(buf, sizeof(buf),
                "%s (%s, min %.1f mm, clearance %.1f mm, under-contour %.1f mm, %.2f g/cm³)",
                m.name.c_str(), thickness, m.min_thickness_mm, m.edge_clearance_mm,
                m.under_contour_mm, m.density_g_cm3);
  return buf;
}

std::string zone_problem(const ClearanceZone& z) {
  if (!z.center.allFinite()) return "the zone's centre is not a point";
  return range_problems("the", z);
}

double clearance_at(const Eigen::Vector3d& p, double base_mm,
                    const std::vector<ClearanceZone>& zones) {
  double c = base_mm;
  for (const ClearanceZone& z : zones) {
    const double beyond = (p - z.center).norm() - z.radius_mm;
    const double w = std::clamp(1.0 - beyond / kZoneBlendMm, 0.0, 1.0);
    c = std::max(c, base_mm + w * (z.clearance_mm - base_mm));
  }
  return c;
}

}  // namespace cranioplan
