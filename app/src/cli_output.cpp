#include "cli_output.h"

#include <CLI/CLI.hpp>
#include <iostream>
#include <map>
#include <sstream>

#include "cranioplan/algorithms/io/load_skull.h"

namespace cranioplan::cli {
namespace {
void print_human(const Json& j, const std::string& prefix) {
  for (auto it = j.begin(); it != j.end(); ++it) {
    const std::string key = prefix.empty() ? it.key() : prefix + "." + it.key();
    const Json& v = it.value();
    if (v.is_object()) {
      print_human(v, key);
    } else if (v.is_string()) {
      std::cout << key << ": " << v.get<std::string>() << "\n";
    } else {
      std::cout << key << ": " << v.dump() << "\n";
    }
  }
}
}  // namespace

void print_result(const Json& result, bool json) {
  if (json)
    std::cout << result.dump(2) << std::endl;
  else
    print_human(result, "");
}

void print_error(const std::string& message, int code, bool json) {
  if (json) std::cout << Json{{"error", message}, {"exit_code", code}}.dump(2) << std::endl;
  std::cerr << "cranioplan-cli: " << message << std::endl;
}

void print_warnings(const std::vector<std::string>& warnings, bool json) {
  if (json) return;  // included in the JSON result instead
  for (const auto& w : warnings) std::cerr << "warning: " << w << "\n";
}

void add_units_option(CLI::App* cmd, double& mesh_unit_mm) {
  std::map<std::string, double> units;
  std::string names;
  for (const LengthUnit& u : length_units()) {
    units[u.name] = u.mm;
    names += std::string(names.empty() ? "" : ", ") + u.name;
  }
  cmd->add_option("--units", mesh_unit_mm,
                  "length unit of a mesh file: " + names +
                      " (default mm; a skull of the wrong size "
                      "is refused, naming the unit it looks to be in)")
      ->transform(CLI::CheckedTransformer(units));
}

void add_series_option(CLI::App* cmd, std::string& series_uid) {
  cmd->add_option("--series", series_uid,
                  "a DICOM folder's series to read, by its SeriesInstanceUID (default: the "
                  "largest CT series; `series FOLDER` lists them)");
}

Eigen::Vector3d parse_point(const std::string& text, const std::string& option) {
  std::stringstream in(text);
  Eigen::Vector3d p;
  char c1 = 0, c2 = 0;
  if (!(in >> p.x() >> c1 >> p.y() >> c2 >> p.z()) || c1 != ',' || c2 != ',' || !p.allFinite())
    throw CLI::ValidationError(option, "expected x,y,z in mm, got '" + text + "'");
  return p;
}

}  // namespace cranioplan::cli
