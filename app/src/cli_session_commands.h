#pragma once
// The session subcommands of cranioplan-cli: replay, verify, audit, training-report.
#include <vector>

#include "cli_implant_commands.h"
#include "cranioplan/sessions/plan_state.h"

namespace cranioplan::cli {

/// Exit code of `verify` when a check fails.
constexpr int kVerifyFailed = 4;

std::vector<Subcommand> add_session_commands(CLI::App& app, const bool& json);

/// The plan's state in a few lines: steps done, plane, markers, implant, quality, exports.
Json plan_state_json(const PlanState& state);

}  // namespace cranioplan::cli
