#pragma once
// Private: runs a reader in a child process, so that a library that ends the process on a
// malformed file (an `assert` in GDCM, a segmentation fault) costs the reading, not the program.
//
// The child is a fork of the caller. It reports through a pipe: the file it is about to hand to
// the library (so that a death names that file), and at the end either its result (bytes the
// job serialised) or the InputError it threw. The parent turns every other end — a signal, an
// exit without a result, no progress for `stall_seconds` (the child is then killed) — into an
// InputError naming the file being read and what the library printed last.
#include <functional>
#include <string>

namespace cranioplan::detail {

/// What the job running in the child can send back.
class ChildReport {
 public:
  explicit ChildReport(int fd) : fd_(fd) {}
  /// The file the job is about to read: named by the message if the child dies in it.
  void reading(const std::string& file);
  /// The job's result. Called once, at the end.
  void result(const std::string& bytes);

 private:
  int fd_;
};

/// Runs `job` in a child process and returns the bytes it passed to ChildReport::result.
/// An InputError the job throws is thrown again here; `path` is the input named when the child
/// dies before saying which file it was reading, `reader` names the reader in the message
/// ("the DICOM library (GDCM)"). Throws InputError on any abnormal end.
std::string run_isolated(const std::string& path, const std::string& reader,
                         const std::function<void(ChildReport&)>& job,
                         double stall_seconds = 120.0);

/// In the child: while it lives, the process may map at most `extra_bytes` more than it has
/// mapped now, so that a library that believes a malformed length (a 4 GiB element in a file of
/// 2 kB) fails to allocate (std::bad_alloc) instead of zero-filling gigabytes. Restores the limit
/// it found when it ends.
class AddressSpaceBudget {
 public:
  explicit AddressSpaceBudget(double extra_bytes);
  ~AddressSpaceBudget();
  AddressSpaceBudget(const AddressSpaceBudget&) = delete;
  AddressSpaceBudget& operator=(const AddressSpaceBudget&) = delete;

 private:
  unsigned long long saved_soft_ = 0;
  bool set_ = false;
};

/// Little helpers to serialise a result into bytes and read it back (native byte order: the
/// bytes never leave the machine).
class ByteWriter {
 public:
  template <class T>
  void pod(const T& v) {
    out_.append(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  void str(const std::string& s);
  void raw(const void* data, size_t size) {
    if (size > 0) out_.append(static_cast<const char*>(data), size);
  }
  std::string take() { return std::move(out_); }

 private:
  std::string out_;
};

class ByteReader {
 public:
  explicit ByteReader(const std::string& in) : in_(in) {}
  template <class T>
  T pod() {
    T v;
    raw(&v, sizeof(T));
    return v;
  }
  std::string str();
  void raw(void* data, size_t size);

 private:
  const std::string& in_;
  size_t at_ = 0;
};

}  // namespace cranioplan::detail
