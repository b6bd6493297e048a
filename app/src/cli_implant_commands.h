#pragma once
// The implant subcommands of cranioplan-cli: smooth, implant, qa, compare, inject-defect.
#include <vector>

#include "cli_run.h"

namespace cranioplan::cli {

std::vector<Subcommand> add_implant_commands(CLI::App& app, const bool& json);

}  // namespace cranioplan::cli
