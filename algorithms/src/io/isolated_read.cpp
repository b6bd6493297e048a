#include "isolated_read.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>

#include "cranioplan/model/error.h"

// Present only in a sanitizer build: the function a sanitizer calls before it ends the process
// on an error it reports (libFuzzer sets one that saves the input as a crash of its own).
extern "C" void __sanitizer_set_death_callback(void (*callback)(void)) __attribute__((weak));

namespace cranioplan::detail {
namespace {

// Records on the pipe: one tag byte, an 8-byte length, the payload.
constexpr char kReading = 'F', kResult = 'R', kInputError = 'E', kOtherError = 'X';

void write_all(int fd, const char* data, size_t size) {
  while (size > 0) {
    const ssize_t n = ::write(fd, data, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) _exit(3);  // the parent is gone: nobody to report to
    data += n;
    size -= static_cast<size_t>(n);
  }
}

void write_record(int fd, char tag, const std::string& bytes) {
  const uint64_t size = bytes.size();
  write_all(fd, &tag, 1);
  write_all(fd, reinterpret_cast<const char*>(&size), sizeof(size));
  write_all(fd, bytes.data(), bytes.size());
}

// The last thing the child printed before it ended (an assertion's text), without the program's
// name and the library's source path, for the message.
std::string last_words(FILE* err) {
  std::string text;
  std::fflush(err);
  std::rewind(err);
  char buf[4096];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof(buf), err)) > 0) {
    text.append(buf, n);
    if (text.size() > (1u << 20)) text.erase(0, text.size() - 4096);
  }
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  const size_t line = text.rfind('\n');
  if (line != std::string::npos) text.erase(0, line + 1);
  const size_t assertion = text.find("Assertion");
  if (assertion != std::string::npos) text.erase(0, assertion);
  if (text.size() > 240) text = text.substr(0, 240) + "...";
  return text;
}

std::string signal_name(int sig) {
  switch (sig) {
    case SIGABRT:
      return "it aborted (SIGABRT)";
    case SIGSEGV:
      return "it crashed (SIGSEGV)";
    case SIGBUS:
      return "it crashed (SIGBUS)";
    case SIGFPE:
      return "it crashed (SIGFPE)";
    case SIGKILL:
      return "it was killed (SIGKILL; out of memory?)";
    default:
      return "it ended on signal " + std::to_string(sig);
  }
}

[[noreturn]] void run_child(int fd, FILE* err, const std::function<void(ChildReport&)>& job) {
  // The child dies of what it meets: a crash handler inherited from the parent (a fuzzer's, a
  // sanitizer's) would report the parent's state, and a timer would fire in the wrong process.
  for (int sig : {SIGABRT, SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGTRAP, SIGALRM, SIGPIPE})
    ::signal(sig, SIG_DFL);
  if (__sanitizer_set_death_callback) __sanitizer_set_death_callback(nullptr);
  // What the library prints goes to a file the parent reads, not to the user's terminal.
  if (err) ::dup2(fileno(err), STDERR_FILENO);
  ChildReport report(fd);
  try {
    job(report);
  } catch (const InputError& e) {
    ByteWriter w;
    w.str(e.path());
    w.str(e.problem());
    write_record(fd, kInputError, w.take());
  } catch (const std::exception& e) {
    write_record(fd, kOtherError, e.what());
  }
  // No destructors or exit handlers of the parent's objects run in the child.
  _exit(0);
}

}  // namespace

void ChildReport::reading(const std::string& file) { write_record(fd_, kReading, file); }
void ChildReport::result(const std::string& bytes) { write_record(fd_, kResult, bytes); }

std::string run_isolated(const std::string& path, const std::string& reader,
                         const std::function<void(ChildReport&)>& job, double stall_seconds) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0)
    throw InputError(path, std::string("could not start its reader: ") + std::strerror(errno));
  FILE* err = std::tmpfile();
  std::fflush(nullptr);  // nothing buffered in the parent is written twice by the child
  const pid_t pid = ::fork();
  if (pid < 0) {
    const int e = errno;
    ::close(fds[0]);
    ::close(fds[1]);
    if (err) std::fclose(err);
    throw InputError(path, std::string("could not start its reader: ") + std::strerror(e));
  }
  if (pid == 0) {
    ::close(fds[0]);
    run_child(fds[1], err, job);
  }
  ::close(fds[1]);

  std::string current = path, result, buffer;
  std::string error_path, error_problem, other_error;
  bool got_result = false, got_error = false, stalled = false;
  const int timeout_ms = static_cast<int>(stall_seconds * 1000.0);
  char chunk[1 << 16];
  for (;;) {
    pollfd p{fds[0], POLLIN, 0};
    const int ready = ::poll(&p, 1, timeout_ms);
    if (ready < 0 && errno == EINTR) continue;
    if (ready == 0) {
      stalled = true;
      ::kill(pid, SIGKILL);
      break;
    }
    const ssize_t n = ::read(fds[0], chunk, sizeof(chunk));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    buffer.append(chunk, static_cast<size_t>(n));
    // Take every complete record off the front of the buffer (the result, the large one, is
    // moved out, not copied).
    while (buffer.size() >= 9) {
      uint64_t size;
      std::memcpy(&size, buffer.data() + 1, sizeof(size));
      if (buffer.size() - 9 < size) break;
      const char tag = buffer[0];
      std::string payload;
      if (buffer.size() - 9 == size) {
        buffer.erase(0, 9);
        payload = std::move(buffer);
        buffer.clear();
      } else {
        payload = buffer.substr(9, size);
        buffer.erase(0, 9 + size);
      }
      if (tag == kReading) {
        current = std::move(payload);
      } else if (tag == kResult) {
        result = std::move(payload);
        got_result = true;
      } else if (tag == kInputError) {
        ByteReader r(payload);
        error_path = r.str();
        error_problem = r.str();
        got_error = true;
      } else if (tag == kOtherError) {
        other_error = std::move(payload);
      }
    }
  }
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  const std::string said = err ? last_words(err) : std::string();
  if (err) std::fclose(err);

  if (got_error) throw InputError(error_path, error_problem);
  if (got_result && !stalled) return result;
  if (!other_error.empty())
    throw InputError(current, reader + " could not read this file: " + other_error);
  const std::string why =
      stalled ? "it made no progress for " + std::to_string(static_cast<int>(stall_seconds)) +
                    " s and was stopped"
      : WIFSIGNALED(status)
          ? signal_name(WTERMSIG(status))
          : "it ended (exit status " + std::to_string(WEXITSTATUS(status)) + ") without a result";
  throw InputError(current, reader + " could not read this file: " + why +
                                (said.empty() ? std::string() : " (" + said + ")") +
                                "; the file is malformed, or of a kind " + reader +
                                " does not know");
}

AddressSpaceBudget::AddressSpaceBudget(double extra_bytes) {
  std::ifstream statm("/proc/self/statm");
  unsigned long long pages = 0;
  rlimit lim{};
  if (!(statm >> pages) || ::getrlimit(RLIMIT_AS, &lim) != 0) return;
  const double wanted =
      static_cast<double>(pages) * static_cast<double>(::sysconf(_SC_PAGESIZE)) + extra_bytes;
  if (lim.rlim_max != RLIM_INFINITY && wanted >= static_cast<double>(lim.rlim_max)) return;
  if (lim.rlim_cur != RLIM_INFINITY && wanted >= static_cast<double>(lim.rlim_cur)) return;
  saved_soft_ = lim.rlim_cur;
  lim.rlim_cur = static_cast<rlim_t>(wanted);
  set_ = ::setrlimit(RLIMIT_AS, &lim) == 0;
}

AddressSpaceBudget::~AddressSpaceBudget() {
  if (!set_) return;
  rlimit lim{};
  ::getrlimit(RLIMIT_AS, &lim);
  lim.rlim_cur = static_cast<rlim_t>(saved_soft_);
  ::setrlimit(RLIMIT_AS, &lim);
}

void ByteWriter::str(const std::string& s) {
  pod<uint64_t>(s.size());
  out_.append(s);
}

std::string ByteReader::str() {
  const uint64_t n = pod<uint64_t>();
  if (n > in_.size() - at_) throw Error("isolated reader: a truncated report");
  std::string s = in_.substr(at_, n);
  at_ += n;
  return s;
}

void ByteReader::raw(void* data, size_t size) {
  if (size > in_.size() - at_) throw Error("isolated reader: a truncated report");
  if (size == 0) return;  // an empty vector's data() may be null
  std::memcpy(data, in_.data() + at_, size);
  at_ += size;
}

}  // namespace cranioplan::detail
