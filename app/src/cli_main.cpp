// cranioplan-cli: the planning pipeline without a window. Exit codes: 0 success, 1 the
// computation gave no usable result (its status says why), 2 usage error, 3 bad input file.
#include <CLI/CLI.hpp>
#include <filesystem>
#include <new>
#include <vector>

#include "cli_evaluation.h"
#include "cli_implant_commands.h"
#include "cli_mesh_commands.h"
#include "cli_output.h"
#include "cli_session_commands.h"
#include "cranioplan/algorithms/geometry/huge_pages.h"
#include "cranioplan/model/error.h"

namespace cranioplan::cli {

int run(int argc, char** argv) {
  CLI::App app{"cranioplan-cli " CRANIOPLAN_VERSION
               " — patient-specific cranial implant planning without a window.\n"
               "Exit codes: 0 success, 1 no usable result, 2 usage error, 3 bad input file."};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("cranioplan-cli ") + CRANIOPLAN_VERSION);
  bool json = false;
  std::vector<Subcommand> subcommands = add_mesh_commands(app, json);
  for (auto* add : {&add_implant_commands, &add_evaluation_commands, &add_session_commands})
    for (auto& c : (*add)(app, json)) subcommands.push_back(std::move(c));

  for (auto* sub : app.get_subcommands([](CLI::App*) { return true; }))
    sub->add_flag("--json", json, "print one JSON object on stdout");

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kUsage;
  }

  try {
    for (const auto& c : subcommands)
      if (c.app->parsed()) return c.run();
  } catch (const CLI::ValidationError& e) {
    print_error(e.what(), kUsage, json);
    return kUsage;
  } catch (const InputError& e) {
    print_error(e.what(), kBadInput, json);
    return kBadInput;
  } catch (const Error& e) {
    print_error(e.what(), kBadInput, json);
    return kBadInput;
  } catch (const std::filesystem::filesystem_error& e) {
    print_error(e.what(), kBadInput, json);
    return kBadInput;
  } catch (const std::bad_alloc&) {
    print_error("out of memory", kUnusable, json);
    return kUnusable;
  } catch (const std::exception& e) {  // a defect of ours: said, not an abort
    print_error(std::string("unexpected error (please report it): ") + e.what(), kUnusable, json);
    return kUnusable;
  }
  return kUsage;
}

}  // namespace cranioplan::cli

int main(int argc, char** argv) {
  cranioplan::start_with_huge_pages(argv);
  return cranioplan::cli::run(argc, argv);
}
