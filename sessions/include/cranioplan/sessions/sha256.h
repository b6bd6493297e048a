#pragma once
// SHA-256 (OpenSSL) as lower-case hex: file identity for inputs and exports, and the links of
// the session journal's hash chain.
#include <string>
#include <string_view>

namespace cranioplan {

std::string sha256_hex(std::string_view bytes);
/// SHA-256 of a file's bytes; of a folder (a DICOM series), of its files' relative paths and
/// SHA-256s in name order. Throws InputError for a missing or unreadable file.
std::string sha256_file(const std::string& path);

}  // namespace cranioplan
