#pragma once
// Pieces the planning subcommands of cranioplan-cli share (implant, evaluation).
#include <string>

#include "cranioplan/algorithms/planning/autoplan.h"

namespace CLI {
class App;
}

namespace cranioplan::cli {

/// Meshes, or label volumes (e.g. SkullFix NRRD masks) turned into surfaces with every piece
/// kept.
SkullMesh load_any(const std::string& path);

/// --fit-to-bone MM and --local-registration MM of the automatic planner.
void add_fit_option(CLI::App* cmd, AutoplanParams& params);

}  // namespace cranioplan::cli
