#pragma once
// Session commands: one small immutable value per user operation — a type tag, a per-type
// version and its parameters (JSON, the same fields as the algorithms' Params structs), markers
// by stable id, never pointers or mesh handles. What was done, not which widget was clicked, so a
// plan replays on any screen and in later versions.
#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "cranioplan/algorithms/alignment/fit_sagittal_plane.h"
#include "cranioplan/algorithms/alignment/register_icp.h"
#include "cranioplan/algorithms/implant/build_implant.h"
#include "cranioplan/algorithms/implant/casting_mould.h"
#include "cranioplan/algorithms/implant/smooth_markers.h"
#include "cranioplan/algorithms/io/extract_bone_surface.h"
#include "cranioplan/algorithms/planning/propose_markers.h"
#include "cranioplan/algorithms/planning/shape_prior.h"
#include "cranioplan/model/marker.h"
#include "cranioplan/model/plane.h"
#include "cranioplan/model/rigid_transform.h"
#include "cranioplan/sessions/plan_files.h"

namespace cranioplan {

enum class CommandType {
  LoadSkull,
  SetLandmark,
  ClearLandmark,
  FitPlane,
  AdjustPlane,
  Mirror,
  Register,
  MoveMirrored,
  SetClipPlane,
  AddMarker,
  MoveMarker,
  DeleteMarker,
  RetypeMarker,
  ImportMarkers,
  ClearMarkers,
  ProposeMarkers,
  SmoothMarkers,
  BuildImplant,
  ExportImplant,
  GoToStep,
  CompleteStep,
  Note,
  AttachCt,
  Approve,
};

/// Every command type, in the order above.
const std::vector<CommandType>& all_command_types();
/// The JSON tag, e.g. "load_skull".
const char* type_tag(CommandType type);
std::optional<CommandType> command_type_from_tag(const std::string& tag);
/// The version this program writes for the type. Older versions are read as recorded (the
/// journal's hashes cover them) and applied by their rules (docs/SESSIONS.md, "Command
/// versions").
int current_version(CommandType type);

/// When, by whom and in which wizard step a command was done. Not part of what the command
/// computes: replay ignores it; audit and training reports read it.
struct CommandMeta {
  int step = 0;            ///< wizard step (1..9) the command belongs to
  std::string started;     ///< ISO-8601 UTC with milliseconds
  std::string ended;       ///< ISO-8601 UTC with milliseconds
  double duration_ms = 0;  ///< time the operation took (merged drags: from first to last)
  std::string user;        ///< who did it
};

struct Command {
  CommandType type = CommandType::Note;
  int version = 1;
  Json params = Json::object();
  CommandMeta meta;
};

/// Plain words for menus and timelines: "Move marker 12", "Build implant (shell)".
std::string describe(const Command& command);

Json to_json(const Command& command);
/// Reads a command; `where` names it in errors ("plan.json: commands[3]"). Throws SessionError
/// for an unknown type, an unknown version, or a missing or mistyped parameter.
Command command_from_json(const Json& j, const std::string& where);

/// Reads parameters of one command, naming the command and the parameter in errors.
class ParamReader {
 public:
  ParamReader(const Json& params, std::string where) : params_(params), where_(std::move(where)) {}
  bool has(const char* name) const;
  double number(const char* name) const;  ///< null reads as NaN
  int integer(const char* name) const;
  bool boolean(const char* name) const;
  std::string string(const char* name) const;
  Eigen::Vector3d vector3(const char* name) const;
  const Json& value(const char* name) const;
  const std::string& where() const { return where_; }

 private:
  const Json& params_;
  std::string where_;
};

// The parameter forms of the algorithms' Params structs (every field written, every field
// required when read back, NaN as null).
Json params_to_json(const ExtractBoneSurfaceParams& p);
Json params_to_json(const PlaneFitParams& p);
Json params_to_json(const RegisterParams& p);
Json params_to_json(const SmoothParams& p);
Json params_to_json(const ProposeParams& p);
Json params_to_json(const ImplantParams& p);
void params_from_json(const ParamReader& r, ExtractBoneSurfaceParams& p);
void params_from_json(const ParamReader& r, PlaneFitParams& p);
void params_from_json(const ParamReader& r, RegisterParams& p);
void params_from_json(const ParamReader& r, SmoothParams& p);
void params_from_json(const ParamReader& r, ProposeParams& p);
void params_from_json(const ParamReader& r, ImplantParams& p);
/// A build's material, clearance zones, perforations and tabs as build_implant records them; read
/// back with their ranges checked (a SessionError names the problem).
Json to_json(const Material& m);
Json to_json(const ClearanceZone& z);
Json to_json(const PerforationParams& p);
Json to_json(const TabParams& p);
Json to_json(const MouldParams& p);
MouldParams mould_from_json(const ParamReader& r);
Material material_from_json(const ParamReader& r);
PerforationParams perforations_from_json(const ParamReader& r);
TabParams tabs_from_json(const ParamReader& r);
ClearanceZone clearance_zone_from_json(const ParamReader& r);

/// Builders: the only way the wizard and the CLI make commands.
namespace commands {
/// `sha256` may be empty: the session fills it in when the command is pushed.
Command load_skull(const std::string& path, const ExtractBoneSurfaceParams& import = {},
                   const std::string& sha256 = "");
/// name: "nasion", "orbit_left", "orbit_right" or "midline" (midline points accumulate).
Command set_landmark(const std::string& name, const Eigen::Vector3d& position);
Command clear_landmark(const std::string& name);
Command fit_plane(const PlaneFitParams& params = {});
/// Turns the plane about `axis` (through the plane's point nearest the skull's centre) by
/// `angle_deg`, then moves it `shift_mm` along its normal.
Command adjust_plane(const Eigen::Vector3d& axis, double angle_deg, double shift_mm);
Command mirror();
Command register_mirror(const RegisterParams& params = {});
/// Moves the mirrored skull by hand: a turn about `axis` through `center` and a translation.
Command move_mirrored(const Eigen::Vector3d& axis, double angle_deg, const Eigen::Vector3d& center,
                      const Eigen::Vector3d& translation);
Command set_clip_plane(const Plane& plane);
Command clear_clip_plane();
/// Placed at `position`, snapped onto the type's surface (edge: original, surface: mirrored).
Command add_marker(MarkerType type, const Eigen::Vector3d& position);
Command move_marker(int id, const Eigen::Vector3d& position);
Command delete_marker(int id);
Command retype_marker(int id, MarkerType type);
Command import_markers(const std::vector<Marker>& markers, const std::string& source,
                       const std::string& sha256);
Command clear_markers();
/// `shape_model`: a model of the normal skull (.cpsm) to guide the surfaces, recorded as an input
/// of the plan (its path and SHA-256: `shape_model_sha256` when given, else the file's hash)
/// with the weight it is averaged in with (ProposeParams::shape_model_weight) and `prior`, how
/// it is fitted and judged.
Command propose_markers(const ProposeParams& params = {}, const std::string& shape_model = "",
                        const std::string& shape_model_sha256 = "",
                        const ShapePriorParams& prior = {});
Command smooth_markers(const SmoothParams& params, bool project_onto_mirror = true);
Command build_implant(const ImplantParams& params = {});
/// `sha256` may be empty: the session writes the file and records the hash of its bytes.
/// With `mould` (a .3mf path only), the package also holds the two halves of a casting mould.
/// A surgeon's sign-off of the implant as it stands (`implant_sha256`, the implant's STL hash,
/// is filled in when the command is done): who (`by`) in what role. Any change of the implant
/// afterwards withdraws it.
Command approve(const std::string& by, const std::string& role,
                const std::string& implant_sha256 = "");
Command export_implant(const std::string& path, const std::string& sha256 = "",
                       const std::optional<MouldParams>& mould = std::nullopt);
Command go_to_step(int step);
Command complete_step(int step);
Command note(const std::string& text);
/// The CT of a plan made from a mesh, for the slice views: checked to lie on the skull.
Command attach_ct(const std::string& path, const ExtractBoneSurfaceParams& import = {},
                  const std::string& sha256 = "");
}  // namespace commands

}  // namespace cranioplan
