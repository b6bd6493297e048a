#pragma once
#include <string>

namespace cranioplan {

/// Writes bytes to a temporary file beside `path`, flushes it to disk and renames it over
/// `path`, so a reader never sees a half-written file. Throws InputError on failure.
void write_file_atomically(const std::string& path, const std::string& bytes);

}  // namespace cranioplan
