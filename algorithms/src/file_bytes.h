#pragma once
// Private helpers of the readers: gzip inflation and extensions.
#include <string>

namespace cranioplan::detail {

/// Inflates gzip (or zlib) data. `expected_size` (when > 0) bounds the output: more data than
/// that is an error, which stops a corrupt stream from filling memory.
std::string gunzip(const std::string& path, const char* data, size_t size,
                   size_t expected_size = 0);

/// Lower-case extension including the dot (".stl"); ".nii.gz" for a gzipped NIfTI.
std::string lower_extension(const std::string& path);

}  // namespace cranioplan::detail
