#include "io/file_bytes.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <functional>

#include "cranioplan/algorithms/io/file_io.h"
#include "cranioplan/model/error.h"
#include "io/volume_formats.h"
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

// Inflated in pieces of at most a megabyte, in order: the pieces make the whole, also when the
// output is a few bytes over a megabyte; the announced size still bounds it.
TEST(FileBytes, InflatedPiecesMakeTheWhole) {
  std::string text;
  for (int i = 0; i < (1 << 20) + 4099; ++i) text += static_cast<char>((i * 131) % 251);
  const std::string gz = test::gzip(text);
  std::string joined;
  size_t pieces = 0, largest = 0;
  const size_t n = detail::gunzip_each("x.gz", gz.data(), gz.size(), text.size(),
                                       [&](const char* piece, size_t size) {
                                         joined.append(piece, size);
                                         ++pieces;
                                         largest = std::max(largest, size);
                                       });
  EXPECT_EQ(n, text.size());
  EXPECT_EQ(joined, text);
  EXPECT_GE(pieces, 2u);
  EXPECT_LE(largest, size_t{1} << 20);
  EXPECT_NE(error_of([&] {
              detail::gunzip_each("big.nrrd", gz.data(), gz.size(), 5000,
                                  [](const char*, size_t) {});
            }).find("big.nrrd: compressed data holds more than the 5,000 bytes"),
            std::string::npos);
}

// Samples whose bytes come in pieces that split them (three bytes at a time for 16-bit samples,
// big-endian) are the samples convert_samples gives from the whole; too few bytes give its
// message.
TEST(FileBytes, SamplesConvertedAsTheirBytesComeAreTheSamplesOfTheWhole) {
  std::string bytes;
  for (int i = 0; i < 1001; ++i) {
    const int16_t v = static_cast<int16_t>(i * 37 - 15000);
    bytes += static_cast<char>((v >> 8) & 0xff);
    bytes += static_cast<char>(v & 0xff);
  }
  std::vector<float> whole, pieces;
  detail::convert_samples("v.nrrd", bytes.data(), bytes.size(), 1001, detail::SampleType::Int16,
                          true, whole);
  detail::SampleStream stream("v.nrrd", 1001, detail::SampleType::Int16, true, pieces);
  for (size_t at = 0; at < bytes.size(); at += 3)
    stream.add(bytes.data() + at, std::min<size_t>(3, bytes.size() - at));
  stream.finish();
  EXPECT_EQ(pieces, whole);
  EXPECT_EQ(whole[1000], 1000.0f * 37 - 15000);

  const std::string expected = error_of([&] {
    std::vector<float> out;
    detail::convert_samples("v.nrrd", bytes.data(), 2001, 1001, detail::SampleType::Int16, true,
                            out);
  });
  EXPECT_NE(expected.find("but the data holds only 2,001 bytes"), std::string::npos) << expected;
  EXPECT_EQ(error_of([&] {
              std::vector<float> out;
              detail::SampleStream cut("v.nrrd", 1001, detail::SampleType::Int16, true, out);
              cut.add(bytes.data(), 1000);
              cut.add(bytes.data() + 1000, 1001);
              cut.finish();
            }),
            expected);
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
