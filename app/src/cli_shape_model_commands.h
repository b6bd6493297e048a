#pragma once
// cranioplan-cli shape-model build / info: a department's model of the normal skull.
#include <vector>

#include "cli_run.h"

namespace cranioplan::cli {

std::vector<Subcommand> add_shape_model_commands(CLI::App& app, const bool& json);

}  // namespace cranioplan::cli
