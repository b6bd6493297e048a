#pragma once
// The implant subcommands of cranioplan-cli: smooth, implant, qa, compare, inject-defect.
#include <CLI/CLI.hpp>
#include <functional>
#include <vector>

namespace cranioplan::cli {

struct Subcommand {
  CLI::App* app;
  std::function<int()> run;  ///< returns the exit code; throws InputError for bad files
};

std::vector<Subcommand> add_implant_commands(CLI::App& app, const bool& json);

}  // namespace cranioplan::cli
