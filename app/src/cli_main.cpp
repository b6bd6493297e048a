// cranioplan-cli: the planning pipeline without a window. Exit codes: 0 success, 1 the
// computation gave no usable result (its status says why), 2 usage error, 3 bad input file.
// The research tools (bench, study, evaluate, merge) are cranioplan-lab's (lab_main.cpp).
#include <CLI/CLI.hpp>
#include <vector>

#include "cli_implant_commands.h"
#include "cli_mesh_commands.h"
#include "cli_run.h"
#include "cli_session_commands.h"
#include "cli_shape_model_commands.h"
#include "cranioplan/algorithms/geometry/huge_pages.h"

int main(int argc, char** argv) {
  using namespace cranioplan::cli;
  cranioplan::start_with_huge_pages(argv);
  CLI::App app{"cranioplan-cli " CRANIOPLAN_VERSION
               " — patient-specific cranial implant planning without a window.\n"
               "Exit codes: 0 success, 1 no usable result, 2 usage error, 3 bad input file."};
  app.set_version_flag("--version", std::string("cranioplan-cli ") + CRANIOPLAN_VERSION);
  bool json = false;
  std::vector<Subcommand> subcommands = add_mesh_commands(app, json);
  for (auto* add : {&add_implant_commands, &add_session_commands, &add_shape_model_commands})
    for (auto& c : (*add)(app, json)) subcommands.push_back(std::move(c));
  for (auto& c : moved_to(app, {"bench", "study", "evaluate", "merge"}, "cranioplan-lab", json))
    subcommands.push_back(std::move(c));
  return run_program(app, subcommands, json, argc, argv);
}
