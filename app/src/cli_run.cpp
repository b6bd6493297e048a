#include "cli_run.h"

#include <filesystem>
#include <new>

#include "cli_output.h"
#include "cranioplan/model/error.h"

namespace cranioplan::cli {

int run_program(CLI::App& app, const std::vector<Subcommand>& subcommands, bool& json, int argc,
                char** argv) {
  app.require_subcommand(1);
  // Every subcommand, nested ones too (shape-model build), takes --json.
  std::vector<CLI::App*> pending{&app};
  while (!pending.empty()) {
    CLI::App* parent = pending.back();
    pending.pop_back();
    for (CLI::App* sub : parent->get_subcommands([](CLI::App*) { return true; })) {
      sub->add_flag("--json", json, "print one JSON object on stdout");
      pending.push_back(sub);
    }
  }
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

std::vector<Subcommand> moved_to(CLI::App& app, const std::vector<std::string>& names,
                                 const std::string& program, const bool& json) {
  std::vector<Subcommand> out;
  for (const std::string& name : names) {
    CLI::App* cmd = app.add_subcommand(name, "");
    cmd->group("");        // hidden from the help
    cmd->set_help_flag();  // `--help` too says where it went
    cmd->allow_extras();
    cmd->prefix_command();
    out.push_back({cmd, [name, program, &json] {
                     print_error(name + " is a research tool and moved to " + program +
                                     ", built with the project (build/app/" + program +
                                     ", not installed): run `" + program + " " + name +
                                     " --help` (docs/RESEARCH.md)",
                                 kUsage, json);
                     return static_cast<int>(kUsage);
                   }});
  }
  return out;
}

}  // namespace cranioplan::cli
