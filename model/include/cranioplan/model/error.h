#pragma once
// The project's exception types (tier 3 of docs/ARCHITECTURE.md "Errors"): bad files and bad
// sessions. Programmer errors are asserts; expected numerical outcomes are statuses in a Result.
#include <stdexcept>
#include <string>

namespace cranioplan {

/// Base of every exception Cranioplan throws on purpose. Caught once at the app boundary.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

/// A file that cannot be used: missing, empty, truncated, malformed, or with unusable content.
/// The message always starts with the file name, e.g.
/// "skull.stl: file ends after 1,203 of 40,000 triangles".
class InputError : public Error {
 public:
  InputError(const std::string& path, const std::string& problem);
  const std::string& path() const { return path_; }
  const std::string& problem() const { return problem_; }

 private:
  std::string path_;
  std::string problem_;
};

/// Formats an integer with thousands separators ("40,000") for messages a person reads.
std::string format_count(long long value);

}  // namespace cranioplan
