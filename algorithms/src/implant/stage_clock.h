#pragma once
// How long each stage of a build took, in the order the stages ran (ImplantResult and
// TrimToBoneResult::stage_seconds: bench's profile of a committed drag).
#include <chrono>
#include <string>
#include <utility>
#include <vector>

namespace cranioplan {

/// Appends each stage's seconds since the one before (or since `start` for the first) to `out`.
class StageClock {
 public:
  explicit StageClock(
      std::vector<std::pair<std::string, double>>& out,
      std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now())
      : out_(out), last_(start) {}
  void mark(const char* stage) {
    const auto now = std::chrono::steady_clock::now();
    out_.emplace_back(stage, std::chrono::duration<double>(now - last_).count());
    last_ = now;
  }

 private:
  std::vector<std::pair<std::string, double>>& out_;
  std::chrono::steady_clock::time_point last_;
};

}  // namespace cranioplan
