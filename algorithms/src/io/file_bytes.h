#pragma once
// Private helpers of the readers: gzip inflation, extensions and binary sample types.
#include <cstddef>
#include <cstdio>
#include <functional>
#include <memory>
#include <string>

namespace cranioplan::detail {

/// A file read in pieces, front to back, with read_file_bytes's messages: the constructor
/// throws InputError for a missing file, a folder, an unreadable or empty file; read() for a
/// file that ends (or fails) early, saying after how many bytes.
class FileReader {
 public:
  explicit FileReader(const std::string& path);
  size_t size() const { return size_; }
  /// The next n bytes.
  void read(char* into, size_t n);

 private:
  std::string path_;
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file_;
  size_t size_ = 0, done_ = 0;
};

/// Inflates gzip (or zlib) data. `expected_size` (when > 0) bounds the output: more data than
/// that is an error, which stops a corrupt stream from filling memory.
std::string gunzip(const std::string& path, const char* data, size_t size,
                   size_t expected_size = 0);
/// The same, the output handed to `consume` in order, a megabyte or less at a time, and never
/// held whole; returns how many bytes it gave.
size_t gunzip_each(const std::string& path, const char* data, size_t size, size_t expected_size,
                   const std::function<void(const char*, size_t)>& consume);

/// The binary number types of volume and mesh files (NRRD, NIfTI, PLY...).
enum class SampleType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };
/// Bytes of one sample.
size_t sample_size(SampleType t);

/// Lower-case extension including the dot (".stl"); ".nii.gz" for a gzipped NIfTI.
std::string lower_extension(const std::string& path);

}  // namespace cranioplan::detail
