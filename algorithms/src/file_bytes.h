#pragma once
// Private helpers of the readers: whole-file reads and gzip inflation with messages that name
// the file.
#include <string>

namespace cranioplan::detail {

/// The file's bytes. Throws InputError for a missing file, a folder, an unreadable or empty file.
std::string read_file_bytes(const std::string& path);

/// Inflates gzip (or zlib) data. `expected_size` (when > 0) bounds the output: more data than
/// that is an error, which stops a corrupt stream from filling memory.
std::string gunzip(const std::string& path, const char* data, size_t size,
                   size_t expected_size = 0);

/// Lower-case extension including the dot (".stl"); ".nii.gz" for a gzipped NIfTI.
std::string lower_extension(const std::string& path);

}  // namespace cranioplan::detail
