#include "cranioplan/model/error.h"

#include <cstdlib>

namespace cranioplan {

InputError::InputError(const std::string& path, const std::string& problem)
    : Error(path + ": " + problem), path_(path), problem_(problem) {}

std::string format_count(long long value) {
  const bool negative = value < 0;
  std::string digits = std::to_string(std::llabs(value));
  std::string out;
  const int n = static_cast<int>(digits.size());
  for (int i = 0; i < n; ++i) {
    out.push_back(digits[i]);
    const int remaining = n - 1 - i;
    if (remaining > 0 && remaining % 3 == 0) out.push_back(',');
  }
  return negative ? "-" + out : out;
}

}  // namespace cranioplan
