#pragma once
// Skull files for session tests, written once per test program into a temporary folder.
#include <optional>
#include <string>

#include "cranioplan/sessions/plan_state.h"
#include "cranioplan/sessions/session.h"

namespace cranioplan::test {

/// A light synthetic head (5,120 triangles before the hole) with a round hole, as binary STL.
const std::string& small_skull_stl();
/// The thick synthetic skull with a one-sided 45 mm defect (what the planner is tested on), as
/// binary STL; and its ground-truth implant.
const std::string& defect_skull_stl();
const std::string& defect_implant_stl();
/// The automatic plan of defect_skull_stl() (autoplan_session, user "expert"), saved as a
/// session with its exported implant; made once per test program.
struct PlannedCase {
  std::string session_path, implant_path;
  std::string implant_sha;  ///< SHA-256 of the exported implant file
};
const PlannedCase& planned_defect_case();
/// A folder that lives as long as the test program.
std::string scratch_path(const std::string& name);

/// Everything that defines a plan's state, as JSON, to compare states for equality.
Json fingerprint(const PlanState& state);

/// Where the first command of `type` stands among the session's effective commands.
std::optional<size_t> first_command(const Session& session, CommandType type);

/// Pushes a command and fails the test (with the refusal) when it is refused.
void push_ok(Session& session, Command command);

/// Validates a JSON file against docs/session.schema.json with python3-jsonschema. Returns
/// an empty string when valid, the validator's message otherwise; "skip" when python3 or
/// jsonschema is missing.
std::string validate_session_schema(const std::string& path);
/// The same against any JSON schema file.
std::string validate_json_schema(const std::string& path, const std::string& schema);

}  // namespace cranioplan::test
