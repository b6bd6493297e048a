// cranioplan-lab: the research tools beside the planner, built with it: bench (the pipeline's
// steps timed, and the paper's steps in plain VTK beside them), study (defects injected into
// complete skulls, planned and scored), evaluate (a folder of cases scored against their
// ground truth) and merge (the shards of either, as one run). Exit codes as cranioplan-cli's.
#include <CLI/CLI.hpp>
#include <vector>

#include "cli_bench.h"
#include "cli_evaluation.h"
#include "cli_run.h"
#include "cranioplan/algorithms/geometry/huge_pages.h"

int main(int argc, char** argv) {
  using namespace cranioplan::cli;
  cranioplan::start_with_huge_pages(argv);
  CLI::App app{"cranioplan-lab " CRANIOPLAN_VERSION
               " — research tools for Cranioplan's planner: benchmarks, studies on injected "
               "defects, evaluation against ground truth.\n"
               "Exit codes: 0 success, 1 no usable result, 2 usage error, 3 bad input file."};
  app.set_version_flag("--version", std::string("cranioplan-lab ") + CRANIOPLAN_VERSION);
  bool json = false;
  std::vector<Subcommand> subcommands{add_bench(app, json)};
  for (auto& c : add_evaluation_commands(app, json)) subcommands.push_back(std::move(c));
  return run_program(app, subcommands, json, argc, argv);
}
