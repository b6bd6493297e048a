#pragma once
#include <string>

#include "cli_run.h"
#include "cranioplan/sessions/plan_files.h"

namespace cranioplan::cli {

struct BenchOptions {
  std::string input;  ///< CT volume or mesh; the sample case when empty
  int runs = 5;       ///< repetitions per step; the median is reported
};

/// Times each step of the foundation pipeline (import, STL load vs vtkSTLReader, plane, mirror,
/// register) and returns per-step medians in seconds plus the peak memory.
Json run_bench(const BenchOptions& options);

/// bench [--input FILE] [--runs N]: run_bench, printed.
Subcommand add_bench(CLI::App& app, const bool& json);

}  // namespace cranioplan::cli
