#pragma once
// How cranioplan-cli prints: one JSON object with --json, otherwise "key: value" lines.
#include <string>

namespace CLI {
class App;
}

#include "cranioplan/sessions/plan_files.h"

namespace cranioplan::cli {

/// Exit codes of every subcommand.
enum Exit : int { kOk = 0, kUnusable = 1, kUsage = 2, kBadInput = 3 };

void print_result(const Json& result, bool json);
void print_error(const std::string& message, int code, bool json);
void print_warnings(const std::vector<std::string>& warnings, bool json);

/// --units NAME: a mesh file's length unit (mm, cm, m, in, um), stored as mm per unit.
void add_units_option(CLI::App* cmd, double& mesh_unit_mm);
/// --series UID: the series of a DICOM folder to read (ExtractBoneSurfaceParams::dicom_series).
void add_series_option(CLI::App* cmd, std::string& series_uid);

/// "x,y,z" in mm; throws CLI::ValidationError naming the option otherwise.
Eigen::Vector3d parse_point(const std::string& text, const std::string& option);

}  // namespace cranioplan::cli
