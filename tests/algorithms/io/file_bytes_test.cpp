#include "io/file_bytes.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <functional>

#include "cranioplan/algorithms/io/file_io.h"
#include "cranioplan/model/error.h"
#include "support/test_files.h"

namespace cranioplan {
namespace {

using detail::gunzip;
using namespace std::string_literals;

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(FileBytes, GzipAndZlibInflateToTheBytesThatWentIn) {
  std::string text;
  for (int i = 0; i < 20000; ++i) text += static_cast<char>('a' + (i * 7) % 26);
  const std::string gz = test::gzip(text);
  EXPECT_EQ(gunzip("x.gz", gz.data(), gz.size()), text);
  EXPECT_EQ(gunzip("x.gz", gz.data(), gz.size(), text.size()), text);
}

// The size a header announces bounds the output both ways: a stream that holds more is refused
// before it fills memory, one cut short is refused too.
TEST(FileBytes, TheAnnouncedSizeIsHeldToBothWays) {
  const std::string text(100000, 'z');
  const std::string gz = test::gzip(text);
  EXPECT_NE(error_of([&] {
              gunzip("big.nrrd", gz.data(), gz.size(), 1000);
            }).find("big.nrrd: compressed data holds more than the 1,000 bytes"),
            std::string::npos);
  const std::string cut = gz.substr(0, gz.size() / 2);
  EXPECT_EQ(error_of([&] {
              gunzip("cut.nrrd", cut.data(), cut.size(), text.size());
            }).rfind("cut.nrrd: ", 0),
            0u);
  const std::string noise(64, '\x17');
  EXPECT_EQ(error_of([&] { gunzip("noise.gz", noise.data(), noise.size()); }).rfind("noise.gz", 0),
            0u);
}

TEST(FileBytes, ExtensionsAndSampleSizes) {
  EXPECT_EQ(detail::lower_extension("/a.b/Head.NII.GZ"), ".nii.gz");
  EXPECT_EQ(detail::lower_extension("skull.STL"), ".stl");
  EXPECT_EQ(detail::lower_extension("archive.tar.gz"), ".gz");
  EXPECT_EQ(detail::lower_extension("/a.b/noext"), "");
  EXPECT_EQ(detail::sample_size(detail::SampleType::Int16), 2u);
  EXPECT_EQ(detail::sample_size(detail::SampleType::Float64), 8u);
  EXPECT_EQ(detail::sample_size(detail::SampleType::UInt8), 1u);
}

TEST(FileBytes, ReadingSaysWhyAFileCannotBeRead) {
  test::TempDir dir;
  EXPECT_EQ(error_of([&] { read_file_bytes(dir.path("none.stl")); }),
            dir.path("none.stl") + ": file not found");
  std::filesystem::create_directories(dir.path("folder.stl"));
  EXPECT_EQ(error_of([&] { read_file_bytes(dir.path("folder.stl")); }),
            dir.path("folder.stl") + ": is a folder, not a file");
  test::write_bytes(dir.path("empty.stl"), "");
  EXPECT_EQ(error_of([&] { read_file_bytes(dir.path("empty.stl")); }),
            dir.path("empty.stl") + ": file is empty");
  write_file_atomically(dir.path("a.txt"), "bytes\0kept"s);
  EXPECT_EQ(read_file_bytes(dir.path("a.txt")), "bytes\0kept"s);
  EXPECT_EQ(error_of([&] { write_file_atomically(dir.path("no/such/x.txt"), "x"); }),
            dir.path("no/such/x.txt") + ": folder does not exist");
}

}  // namespace
}  // namespace cranioplan
