#pragma once
// Whole-file reads and atomic writes with messages that name the file.
#include <string>

namespace cranioplan {

/// The file's bytes. Throws InputError for a missing file, a folder, an unreadable or empty file.
std::string read_file_bytes(const std::string& path);

/// Writes bytes to a temporary file beside `path`, flushes it to disk and renames it over
/// `path`, so a reader never sees a half-written file. Throws InputError on failure.
void write_file_atomically(const std::string& path, const std::string& bytes);

}  // namespace cranioplan
