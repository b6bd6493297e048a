#pragma once
// Pieces the planning subcommands of cranioplan-cli share (implant, evaluation).
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "cranioplan/algorithms/planning/autoplan.h"
#include "cranioplan/algorithms/shape/shape_model.h"
#include "cranioplan/model/param_spec.h"

namespace CLI {
class App;
}
namespace cranioplan {
struct LoadedSkull;
}

namespace cranioplan::cli {

/// Meshes, or label volumes (e.g. SkullFix NRRD masks) turned into surfaces with every piece
/// kept.
SkullMesh load_any(const std::string& path);

/// `params` planning on `skull` as read: where its scan ended taken from the report made when
/// it was read (a mesh), not found again.
AutoplanParams planning(const AutoplanParams& params, const LoadedSkull& skull);

/// --shape-model FILE: a model of the normal skull to guide the plan (shape-model build).
void add_shape_model_option(CLI::App* cmd, std::string& path);
/// The model at `path` (read_shape_model's InputError for a bad file); null for an empty path.
std::shared_ptr<const ShapeModel> shape_model_from(const std::string& path);
/// Throws InputError naming `skull_path` when the model was built with that very file: a plan
/// scored against a skull its model has seen would leak the answer.
void refuse_if_in_model(const ShapeModel& model, const std::string& skull_path);

/// The option `s` declares, bound to `value`, its range checked and (unless it may be left unset)
/// its default shown; `prefix` goes before its name ("mould-": --mould-wall).
void add_declared_option(CLI::App* cmd, const ParamSpec& s, double& value,
                         const std::string& prefix);
void add_declared_option(CLI::App* cmd, const ParamSpec& s, int& value, const std::string& prefix);
void add_declared_option(CLI::App* cmd, const ParamSpec& s, bool& value, const std::string& prefix);
/// An option that changes `s`'s value only when given (a material preset's).
void add_declared_option(CLI::App* cmd, const ParamSpec& s, std::optional<double>& value);
/// The options `params`' type declares (for_each_field), bound to its fields.
template <class P>
void add_declared_options(CLI::App* cmd, P& params, const std::string& prefix = "") {
  for_each_field(
      [&](const ParamSpec& s, auto& value) {
        using T = std::decay_t<decltype(value)>;
        if constexpr (std::is_same_v<T, double> || std::is_same_v<T, int> ||
                      std::is_same_v<T, bool>)
          if (s.option) add_declared_option(cmd, s, value, prefix);
      },
      params);
}

/// --fit-to-bone MM and --local-registration MM of the automatic planner.
void add_fit_option(CLI::App* cmd, AutoplanParams& params);

/// --material and the values that change a preset (--clearance, --under-contour,
/// --min-thickness, --plate-thickness, --density), and --clearance-zone X,Y,Z,RADIUS,MM.
struct MaterialOptions {
  std::string material;  ///< preset id or name, or "custom"; empty: none
  std::optional<double> clearance, under_contour, min_thickness, plate_thickness, density;
  std::vector<std::string> zones;
};
/// `for_check`: only what a quality check uses (--material, --clearance, --density, zones).
void add_material_options(CLI::App* cmd, MaterialOptions& o, bool for_check = false);

/// --perforate (the pattern), --hole-diameter, --hole-spacing, --hole-edge-distance,
/// --hole X,Y,Z (repeatable), --no-hole X,Y,Z (repeatable).
struct HoleOptions {
  PerforationParams params;
  std::vector<std::string> added, removed;
};
void add_hole_options(CLI::App* cmd, HoleOptions& o);
/// The perforations the options ask for (a CLI::ValidationError for a bad one).
PerforationParams perforations_from(const HoleOptions& o);
/// --tabs (evenly along the rim), --tab-count, --tab-length, --tab-width, --tab-thickness,
/// --tab-screws, --screw-diameter, --countersink, --tab-midline-distance, --tab-min-bone,
/// --tab X,Y,Z (repeatable: the user's tabs, instead of the even placement).
struct TabOptions {
  TabParams params;
  std::vector<std::string> at;
};
void add_tab_options(CLI::App* cmd, TabOptions& o);
/// The tabs the options ask for (a CLI::ValidationError for a bad one, sizes checked as the
/// material makes them).
TabParams tabs_from(const TabOptions& o, const std::optional<Material>& material);
/// The material and zones the options ask for (a CLI::ValidationError for a bad one); none
/// when no option was given.
std::optional<Material> material_from(const MaterialOptions& o);
std::vector<ClearanceZone> zones_from(const MaterialOptions& o);

}  // namespace cranioplan::cli
