#pragma once
// The evaluation subcommands of cranioplan-lab: evaluate (a folder of cases with their truth),
// study (defects injected into a healthy skull) and merge (the shards of either, as one run).
#include <vector>

#include "cli_run.h"

namespace cranioplan::cli {

std::vector<Subcommand> add_evaluation_commands(CLI::App& app, const bool& json);

}  // namespace cranioplan::cli
