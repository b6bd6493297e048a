#pragma once
#include <string>

#include "cranioplan/sessions/plan_files.h"

namespace cranioplan::cli {

struct BenchOptions {
  std::string input;  ///< CT volume or mesh; the sample case when empty
  int runs = 5;       ///< repetitions per step; the median is reported
};

/// Times each step of the foundation pipeline (import, STL load vs vtkSTLReader, plane, mirror,
/// register) and returns per-step medians in seconds plus the peak memory.
Json run_bench(const BenchOptions& options);

}  // namespace cranioplan::cli
