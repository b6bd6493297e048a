#include "cranioplan/sessions/sha256.h"

#include <gtest/gtest.h>

#include "cranioplan/model/error.h"
#include "support/test_files.h"

namespace cranioplan {
namespace {

// FIPS 180-2's test vectors, and a file hashed as its bytes.
TEST(Sha256, KnownVectorsAndFiles) {
  EXPECT_EQ(sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  test::TempDir dir;
  test::write_bytes(dir.path("abc.bin"), "abc");
  EXPECT_EQ(sha256_file(dir.path("abc.bin")), sha256_hex("abc"));
  EXPECT_THROW(sha256_file(dir.path("missing.bin")), InputError);
}

}  // namespace
}  // namespace cranioplan
