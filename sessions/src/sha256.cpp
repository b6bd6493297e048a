#include "cranioplan/sessions/sha256.h"

#include <openssl/evp.h>

#include <cassert>

#include "cranioplan/algorithms/file_io.h"

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

std::string sha256_file(const std::string& path) { return sha256_hex(read_file_bytes(path)); }

}  // namespace cranioplan
