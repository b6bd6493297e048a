#include "cli_planning.h"

#include <CLI/CLI.hpp>
#include <limits>
#include <sstream>

#include "cli_output.h"
#include "cranioplan/algorithms/io/load_skull.h"
#include "cranioplan/model/error.h"
#include "cranioplan/sessions/sha256.h"

namespace cranioplan::cli {

// Meshes, or label volumes (e.g. SkullFix NRRD masks) turned into surfaces with every piece kept.
SkullMesh load_any(const std::string& path) {
  ExtractBoneSurfaceParams p;
  p.largest_piece_only = false;
  p.min_piece_triangles = 1;
  return load_surface(path, p).mesh;
}

AutoplanParams planning(const AutoplanParams& params, const LoadedSkull& skull) {
  AutoplanParams out = params;
  take_scan_borders(out.propose.detect, skull.report);
  return out;
}

void add_shape_model_option(CLI::App* cmd, std::string& path) {
  cmd->add_option("--shape-model", path,
                  "a model of the normal skull (.cpsm, `shape-model build`) to guide the missing "
                  "bone's surfaces; a poor fit falls back to the mirror or the ring, and says so");
}

std::shared_ptr<const ShapeModel> shape_model_from(const std::string& path) {
  if (path.empty()) return nullptr;
  return std::make_shared<const ShapeModel>(read_shape_model(path));
}

void refuse_if_in_model(const ShapeModel& model, const std::string& skull_path) {
  const std::string hash = sha256_file(skull_path);
  for (size_t i = 0; i < model.provenance.skull_sha256.size(); ++i)
    if (model.provenance.skull_sha256[i] == hash)
      throw InputError(skull_path, "the shape model was built with this skull (as " +
                                       model.provenance.skull_names[i] +
                                       "): build one without it to score plans on it");
}

// --fit-to-bone MM: the automatic planner's implant built beyond the rim and trimmed by the bone.
void add_fit_option(CLI::App* cmd, AutoplanParams& params) {
  add_declared_option(cmd, spec_of<ImplantParams>("fit_to_bone_mm"), params.implant.fit_to_bone_mm,
                      "");
  cmd->add_option("--local-registration", params.local_registration_mm,
                  "register the mirror again within this margin of the opening (mm; 0: off)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 200.0));
}

void add_material_options(CLI::App* cmd, MaterialOptions& o, bool for_check) {
  std::string presets;
  for (const Material& m : material_presets()) presets += (presets.empty() ? "" : ", ") + m.id;
  cmd->add_option("--material", o.material,
                  "what the implant is made of: " + presets +
                      " or custom (its thickness, minimum thickness, edge clearance, "
                      "under-contour and density; the values below change them)");
  // Each changes the preset's value only when given.
  add_declared_option(cmd, spec_of<Material>("edge_clearance_mm"), o.clearance);
  if (!for_check) {
    add_declared_option(cmd, spec_of<Material>("under_contour_mm"), o.under_contour);
    add_declared_option(cmd, spec_of<Material>("min_thickness_mm"), o.min_thickness);
    add_declared_option(cmd, spec_of<Material>("thickness_mm"), o.plate_thickness);
  }
  add_declared_option(cmd, spec_of<Material>("density_g_cm3"), o.density);
  cmd->add_option("--clearance-zone", o.zones,
                  "X,Y,Z,RADIUS,MM: the rim within RADIUS mm of the point held MM off the bone "
                  "(repeatable)");
}

std::optional<Material> material_from(const MaterialOptions& o) {
  const bool changed =
      o.clearance || o.under_contour || o.min_thickness || o.plate_thickness || o.density;
  if (o.material.empty() && !changed) return std::nullopt;
  Material m;
  if (!o.material.empty() && o.material != "custom") {
    const std::optional<Material> preset = material_preset(o.material);
    if (!preset) {
      std::string presets;
      for (const Material& p : material_presets()) presets += " " + p.id;
      throw CLI::ValidationError("--material", "unknown material '" + o.material +
                                                   "' (presets:" + presets + ", or custom)");
    }
    m = *preset;
  }
  if (o.clearance) m.edge_clearance_mm = *o.clearance;
  if (o.under_contour) m.under_contour_mm = *o.under_contour;
  if (o.min_thickness) m.min_thickness_mm = *o.min_thickness;
  if (o.plate_thickness) m.thickness_mm = *o.plate_thickness;
  if (o.density) m.density_g_cm3 = *o.density;
  if (const std::string problem = material_problem(m); !problem.empty())
    throw CLI::ValidationError("--material", m.name + ": " + problem);
  return m;
}

std::vector<ClearanceZone> zones_from(const MaterialOptions& o) {
  std::vector<ClearanceZone> zones;
  for (const std::string& text : o.zones) {
    std::stringstream in(text);
    ClearanceZone z;
    char c[4] = {};
    if (!(in >> z.center.x() >> c[0] >> z.center.y() >> c[1] >> z.center.z() >> c[2] >>
          z.radius_mm >> c[3] >> z.clearance_mm) ||
        c[0] != ',' || c[1] != ',' || c[2] != ',' || c[3] != ',')
      throw CLI::ValidationError("--clearance-zone",
                                 "expected X,Y,Z,RADIUS,MM in mm, got '" + text + "'");
    if (const std::string problem = zone_problem(z); !problem.empty())
      throw CLI::ValidationError("--clearance-zone", problem + " ('" + text + "')");
    zones.push_back(z);
  }
  return zones;
}

namespace {

std::string declared_help(const ParamSpec& s) {
  return *s.unit ? std::string(s.help) + " (" + s.unit + ")" : std::string(s.help);
}

// A number the declaration allows: in its range (or 0 where 0 means none).
CLI::Validator declared_check(const ParamSpec& s) {
  std::string shown = "[" + std::string(s.zero_means_none ? "0, " : "") +
                      CLI::detail::to_string(s.min) + " - " + CLI::detail::to_string(s.max) + "]";
  return CLI::Validator(
      [s](std::string& text) -> std::string {
        double v = 0.0;
        if (!CLI::detail::lexical_cast(text, v)) return "Value " + text + " is not a number";
        if (!s.allows(v)) return "Value " + text + " not in range " + s.range_text();
        return {};
      },
      shown);
}

}  // namespace

void add_declared_option(CLI::App* cmd, const ParamSpec& s, double& value,
                         const std::string& prefix) {
  auto* option =
      cmd->add_option("--" + prefix + s.option, value, declared_help(s))->check(declared_check(s));
  if (!s.unset_allowed) option->capture_default_str();
}

void add_declared_option(CLI::App* cmd, const ParamSpec& s, int& value, const std::string& prefix) {
  cmd->add_option("--" + prefix + s.option, value, declared_help(s))
      ->capture_default_str()
      ->check(CLI::Range(static_cast<int>(s.min), static_cast<int>(s.max)));
}

void add_declared_option(CLI::App* cmd, const ParamSpec& s, bool& value,
                         const std::string& prefix) {
  cmd->add_flag("--" + prefix + s.option, value, s.help);
}

void add_declared_option(CLI::App* cmd, const ParamSpec& s, std::optional<double>& value) {
  cmd->add_option("--" + std::string(s.option), value, declared_help(s))->check(declared_check(s));
}

void add_hole_options(CLI::App* cmd, HoleOptions& o) {
  add_declared_options(cmd, o.params);
  cmd->add_option("--hole", o.added, "X,Y,Z: a single hole there (repeatable)");
  cmd->add_option("--no-hole", o.removed,
                  "X,Y,Z: leave out the pattern's hole nearest there (repeatable)");
}

PerforationParams perforations_from(const HoleOptions& o) {
  PerforationParams p = o.params;
  for (const std::string& t : o.added) p.added.push_back(parse_point(t, "--hole"));
  for (const std::string& t : o.removed) p.removed.push_back(parse_point(t, "--no-hole"));
  if (const std::string problem = perforation_problem(p); !problem.empty())
    throw CLI::ValidationError("--perforate", problem);
  return p;
}

void add_tab_options(CLI::App* cmd, TabOptions& o) {
  add_declared_options(cmd, o.params);
  cmd->add_option("--tab", o.at,
                  "X,Y,Z: a tab at the rim point nearest there (repeatable; instead of --tabs' "
                  "even placement)");
}

TabParams tabs_from(const TabOptions& o, const std::optional<Material>& material) {
  TabParams p = o.params;
  for (const std::string& t : o.at) p.positions.push_back(parse_point(t, "--tab"));
  const std::string problem = tab_problem(resolved(
      p, material ? material->min_thickness_mm : std::numeric_limits<double>::quiet_NaN()));
  if (!problem.empty()) throw CLI::ValidationError("--tabs", problem);
  return p;
}

}  // namespace cranioplan::cli
