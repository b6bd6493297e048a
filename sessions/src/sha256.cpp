#include "cranioplan/sessions/sha256.h"

#include <openssl/evp.h>

#include <algorithm>
#include <cassert>
#include <filesystem>
#include <vector>

#include "cranioplan/algorithms/io/file_io.h"
#include "cranioplan/model/error.h"

namespace cranioplan {

std::string sha256_hex(std::string_view bytes) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  const bool ok =
      EVP_Digest(bytes.data(), bytes.size(), digest, &length, EVP_sha256(), nullptr) == 1;
  assert(ok && "EVP_Digest(SHA-256) cannot fail on memory input");
  (void)ok;
  static const char* hex = "0123456789abcdef";
  std::string out(2 * length, '0');
  for (unsigned int i = 0; i < length; ++i) {
    out[2 * i] = hex[digest[i] >> 4];
    out[2 * i + 1] = hex[digest[i] & 15];
  }
  return out;
}

std::string sha256_file(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(path, ec)) return sha256_hex(read_file_bytes(path));
  // A folder (a DICOM series): its files' relative paths and hashes, in name order.
  std::vector<std::string> lines;
  for (fs::recursive_directory_iterator it(path, fs::directory_options::skip_permission_denied, ec),
       end;
       !ec && it != end; it.increment(ec)) {
    std::error_code fec;
    if (!it->is_regular_file(fec)) continue;
    lines.push_back(fs::relative(it->path(), path, fec).generic_string() + '\0' +
                    sha256_hex(read_file_bytes(it->path().string())) + '\n');
  }
  if (ec) throw InputError(path, "the folder cannot be listed: " + ec.message());
  std::sort(lines.begin(), lines.end());
  std::string all;
  for (const std::string& l : lines) all += l;
  return sha256_hex(all);
}

}  // namespace cranioplan
