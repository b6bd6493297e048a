#include "file_bytes.h"

#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>

#include "cranioplan/algorithms/io/file_io.h"
#include "cranioplan/model/error.h"

namespace cranioplan::detail {

namespace fs = std::filesystem;

size_t gunzip_each(const std::string& path, const char* data, size_t size, size_t expected_size,
                   const std::function<void(const char*, size_t)>& consume) {
  z_stream zs{};
  // 15 + 32: accept both gzip and zlib headers.
  if (inflateInit2(&zs, 15 + 32) != Z_OK) throw InputError(path, "cannot start decompression");
  constexpr size_t kBlock = size_t{1} << 20;
  std::unique_ptr<char[]> block(new char[kBlock]);
  zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data));
  zs.avail_in = static_cast<uInt>(std::min<size_t>(size, 0x7fffffff));
  size_t produced = 0;
  while (true) {
    const size_t room = expected_size > 0 ? std::min(kBlock, expected_size - produced) : kBlock;
    if (room == 0) {
      // The stream must end exactly here; one probe byte tells whether more data follows.
      char probe;
      zs.next_out = reinterpret_cast<Bytef*>(&probe);
      zs.avail_out = 1;
      inflate(&zs, Z_NO_FLUSH);
      if (zs.avail_out == 0) {
        inflateEnd(&zs);
        throw InputError(path, "compressed data holds more than the " +
                                   format_count(static_cast<long long>(expected_size)) +
                                   " bytes the header announces");
      }
      break;
    }
    zs.next_out = reinterpret_cast<Bytef*>(block.get());
    zs.avail_out = static_cast<uInt>(room);
    const int rc = inflate(&zs, Z_NO_FLUSH);
    const size_t got = room - zs.avail_out;
    if (got > 0) {
      try {
        consume(block.get(), got);
      } catch (...) {
        inflateEnd(&zs);
        throw;
      }
    }
    produced += got;
    if (rc == Z_STREAM_END) break;
    if (rc != Z_OK) {
      inflateEnd(&zs);
      if (rc == Z_BUF_ERROR)
        throw InputError(path, "compressed data ends early, after " +
                                   format_count(static_cast<long long>(produced)) + " bytes");
      throw InputError(path, std::string("compressed data is corrupt (") +
                                 (zs.msg ? zs.msg : "zlib error") + ")");
    }
  }
  inflateEnd(&zs);
  return produced;
}

std::string gunzip(const std::string& path, const char* data, size_t size, size_t expected_size) {
  // Grown as the data comes, from four times its size (or the announced size, if smaller): a
  // header may announce terabytes over a few bytes of data (docs/FUZZING.md).
  const size_t guess = std::max<size_t>(size * 4, 1 << 16);
  std::string out;
  out.reserve(expected_size > 0 ? std::min(expected_size, guess) : guess);
  gunzip_each(path, data, size, expected_size,
              [&](const char* chunk, size_t n) { out.append(chunk, n); });
  return out;
}

std::string lower_extension(const std::string& path) {
  std::string name = fs::path(path).filename().string();
  std::transform(name.begin(), name.end(), name.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  auto ends_with = [&](const std::string& s) {
    return name.size() >= s.size() && name.compare(name.size() - s.size(), s.size(), s) == 0;
  };
  if (ends_with(".nii.gz")) return ".nii.gz";
  const size_t dot = name.rfind('.');
  return dot == std::string::npos ? std::string() : name.substr(dot);
}

size_t sample_size(SampleType t) {
  switch (t) {
    case SampleType::Int8:
    case SampleType::UInt8:
      return 1;
    case SampleType::Int16:
    case SampleType::UInt16:
      return 2;
    case SampleType::Int32:
    case SampleType::UInt32:
    case SampleType::Float32:
      return 4;
    case SampleType::Float64:
      return 8;
  }
  return 1;
}

FileReader::FileReader(const std::string& path) : path_(path), file_(nullptr, &std::fclose) {
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (ec || !fs::exists(st)) throw InputError(path, "file not found");
  if (fs::is_directory(st)) throw InputError(path, "is a folder, not a file");
  file_.reset(std::fopen(path.c_str(), "rb"));
  if (!file_) throw InputError(path, std::string("cannot open file: ") + std::strerror(errno));
  if (std::fseek(file_.get(), 0, SEEK_END) != 0)
    throw InputError(path, "cannot determine the file size");
  const long size = std::ftell(file_.get());
  if (size < 0 || std::fseek(file_.get(), 0, SEEK_SET) != 0)
    throw InputError(path, "cannot determine the file size");
  size_ = static_cast<size_t>(size);
  if (size_ == 0) throw InputError(path, "file is empty");
}

void FileReader::read(char* into, size_t n) {
  const size_t got = n == 0 ? 0 : std::fread(into, 1, n, file_.get());
  done_ += got;
  if (got != n)
    throw InputError(path_,
                     "read error after " + format_count(static_cast<long long>(done_)) + " bytes");
}

}  // namespace cranioplan::detail

namespace cranioplan {

namespace fs = std::filesystem;

std::string read_file_bytes(const std::string& path) {
  detail::FileReader file(path);
  std::string bytes;
  bytes.resize(file.size());
  file.read(bytes.data(), bytes.size());
  return bytes;
}

void write_file_atomically(const std::string& path, const std::string& bytes) {
  const fs::path target(path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw InputError(path, "folder does not exist");
  const std::string tmp =
      (dir / ("." + target.filename().string() + ".tmp" + std::to_string(::getpid()))).string();
  FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) throw InputError(path, std::string("cannot write: ") + std::strerror(errno));
  const bool ok = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size() &&
                  std::fflush(f) == 0 && ::fsync(::fileno(f)) == 0;
  const bool closed = std::fclose(f) == 0;
  if (!ok || !closed) {
    std::remove(tmp.c_str());
    throw InputError(path, "write failed (disk full?)");
  }
  fs::rename(tmp, target, ec);
  if (ec) {
    std::remove(tmp.c_str());
    throw InputError(path, "cannot replace file: " + ec.message());
  }
}

}  // namespace cranioplan
