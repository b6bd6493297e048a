#pragma once
// The mesh subcommands of cranioplan-cli: info, import-ct, plane, mirror, register, pipeline,
// series, bench.
#include <vector>

#include "cli_implant_commands.h"

namespace cranioplan::cli {

std::vector<Subcommand> add_mesh_commands(CLI::App& app, const bool& json);

}  // namespace cranioplan::cli
