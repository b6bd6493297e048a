#pragma once
// The automatic planner recorded as session commands, so every automatic plan can be reopened,
// edited, replayed and audited like a hand-made one.
#include <string>

#include "cranioplan/algorithms/planning/autoplan.h"
#include "cranioplan/model/landmarks.h"
#include "cranioplan/sessions/session.h"

namespace cranioplan {

struct AutoplanSession {
  enum class Status { Planned, NoDefect, Failed };
  Status status = Status::Failed;
  std::string message;  ///< what happened, or the stage that stopped and why
  Session session;      ///< every command run, whether or not it planned
  /// The opening planned (the engine's detection, whose markers the proposal records), with the
  /// other openings' rays (`other_axes`) for planning them in sessions of their own.
  DefectRegion defect;
  bool planned() const { return status == Status::Planned; }
};

/// The status's name, as AutoplanResult's (status_name): "planned", "no_defect" or "failed".
const char* status_name(AutoplanSession::Status status);

/// Load → landmarks → fit plane → mirror → register → (register around the opening) → inspect
/// → propose markers → build implant → review, and, when `export_path` is not empty, export.
/// The searches are autoplan()'s stages (`autoplan_stages`), each recorded in its command with
/// what it found and how long it took, so the implant is autoplan()'s and a replay searches
/// nothing again. `import`: how the skull file is read (a CT's threshold, a mesh's length unit).
/// `others_planned`: the skull's other openings are planned in sessions of their own, and the
/// messages say so. Throws InputError for a bad skull.
/// `shape_model`: a model of the normal skull (.cpsm) to guide the surfaces, recorded with the
/// proposal as an input of the plan (path and SHA-256).
AutoplanSession autoplan_session(const std::string& skull_path, const Landmarks& landmarks,
                                 const AutoplanParams& params, const std::string& export_path,
                                 const SessionInfo& info = {},
                                 const ExtractBoneSurfaceParams& import = {},
                                 bool others_planned = false, const std::string& shape_model = "");

}  // namespace cranioplan
