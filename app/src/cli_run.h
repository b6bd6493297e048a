#pragma once
// What cranioplan-cli and cranioplan-lab share: a subcommand and how a program runs one (its
// options parsed, its errors said with the exit codes of cli_output.h).
#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

namespace cranioplan::cli {

struct Subcommand {
  CLI::App* app;
  std::function<int()> run;  ///< returns the exit code; throws InputError for bad files
};

/// Parses `argv` for `app` (whose subcommands are `subcommands`, each given --json here) and
/// runs the one named: its exit code, or kUsage for a usage error, kBadInput for a bad file,
/// kUnusable for no memory or a defect of ours (said, not an abort).
int run_program(CLI::App& app, const std::vector<Subcommand>& subcommands, bool& json, int argc,
                char** argv);

/// Subcommands that moved to another program: named on `app` but hidden from its help; run,
/// each says which program has it now (a usage error).
std::vector<Subcommand> moved_to(CLI::App& app, const std::vector<std::string>& names,
                                 const std::string& program, const bool& json);

}  // namespace cranioplan::cli
