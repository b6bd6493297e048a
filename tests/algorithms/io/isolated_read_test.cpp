// A reader run in a child process (algorithms/src/io/isolated_read.h): whatever ends the child — an
// assertion in a library, a crash, a stall — is a message naming the file it was reading, and the
// calling process goes on.
#include "io/isolated_read.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

#include "cranioplan/algorithms/io/read_volume.h"
#include "cranioplan/model/error.h"
#include "support/dicom_writer.h"
#include "support/test_files.h"

namespace cranioplan {
namespace {

using detail::ByteReader;
using detail::ByteWriter;
using detail::ChildReport;
using detail::run_isolated;

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

TEST(IsolatedRead, TheChildsResultComesBackWhole) {
  // Larger than a pipe's buffer many times over, with the progress records before it.
  std::string big(48 << 20, '\0');
  for (size_t i = 0; i < big.size(); ++i) big[i] = static_cast<char>(i * 7919 % 251);
  const std::string back = run_isolated("folder", "the library", [&](ChildReport& report) {
    for (int i = 0; i < 100; ++i) report.reading("slice" + std::to_string(i) + ".dcm");
    ByteWriter w;
    w.str("a header");
    w.pod<double>(1.5);
    w.raw(big.data(), big.size());
    report.result(w.take());
  });
  ByteReader r(back);
  EXPECT_EQ(r.str(), "a header");
  EXPECT_EQ(r.pod<double>(), 1.5);
  std::string data(big.size(), '\0');
  r.raw(data.data(), data.size());
  EXPECT_TRUE(data == big);
  EXPECT_THROW(r.pod<char>(), Error);  // nothing past the end
}

TEST(IsolatedRead, AnInputErrorInTheChildIsThrownAsItWas) {
  try {
    run_isolated("folder", "the library", [](ChildReport& report) {
      report.reading("folder/a.dcm");
      throw InputError("folder/a.dcm", "its rescale slope is not usable");
    });
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.path(), "folder/a.dcm");
    EXPECT_EQ(e.problem(), "its rescale slope is not usable");
  }
}

TEST(IsolatedRead, AnAssertionInTheLibraryNamesTheFileAndTheAssertion) {
  const std::string m = message_of([] {
    run_isolated("folder", "the library", [](ChildReport& report) {
      report.reading("folder/a.dcm");
      report.reading("folder/b.dcm");
      std::fprintf(stderr,
                   "prog: /build/gdcm/Source/gdcmFileMetaInformation.cxx:123: void f(): "
                   "Assertion `0 && \"Impossible\"' failed.\n");
      std::abort();
    });
  });
  EXPECT_EQ(m.rfind("folder/b.dcm: ", 0), 0u) << m;
  EXPECT_NE(m.find("aborted (SIGABRT)"), std::string::npos) << m;
  EXPECT_NE(m.find("(Assertion `0 && \"Impossible\"' failed.)"), std::string::npos) << m;
  EXPECT_EQ(m.find("/build/gdcm"), std::string::npos) << m;
}

TEST(IsolatedRead, ACrashBeforeAnyFileNamesTheFolder) {
  const std::string m = message_of(
      [] { run_isolated("folder", "the library", [](ChildReport&) { std::raise(SIGSEGV); }); });
  EXPECT_EQ(m.rfind("folder: ", 0), 0u) << m;
  EXPECT_NE(m.find("crashed (SIGSEGV)"), std::string::npos) << m;
}

TEST(IsolatedRead, AChildThatStopsMakingProgressIsStopped) {
  const std::string m = message_of([] {
    run_isolated(
        "folder", "the library",
        [](ChildReport& report) {
          report.reading("folder/slow.dcm");
          ::sleep(60);
        },
        0.5);
  });
  EXPECT_EQ(m.rfind("folder/slow.dcm: ", 0), 0u) << m;
  EXPECT_NE(m.find("no progress for 0 s"), std::string::npos) << m;
}

TEST(IsolatedRead, AChildThatExitsWithoutAResultIsAnError) {
  const std::string m =
      message_of([] { run_isolated("folder", "the library", [](ChildReport&) { _exit(7); }); });
  EXPECT_NE(m.find("exit status 7"), std::string::npos) << m;
}

// A budget makes an allocation a malformed length asks for fail in the child, quickly, instead
// of zero-filling gigabytes.
TEST(IsolatedRead, AnAddressSpaceBudgetRefusesAVastAllocation) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer's allocator reports a refused mapping instead of throwing";
#endif
  const std::string back = run_isolated("file", "the library", [](ChildReport& report) {
    std::string said;
    {
      const detail::AddressSpaceBudget budget(256.0 * 1024 * 1024);
      try {
        std::vector<char> vast(size_t{4} << 30);
        said = "allocated";
      } catch (const std::bad_alloc&) {
        said = "refused";
      }
    }
    std::vector<char> after(size_t{512} << 20);  // the limit is lifted again
    said += after.size() == (size_t{512} << 20) ? ", then allocated" : "";
    report.result(said);
  });
  EXPECT_EQ(back, "refused, then allocated");
}

// The input on which Debian's GDCM 3.0.21 asserts in its file meta reader (a libFuzzer finding,
// kept in tests/fuzz/regressions/dicom): beside a good series, it is refused by name and the
// program goes on to read the good series once the file is gone.
TEST(IsolatedRead, AFileTheDicomLibraryAbortsOnIsRefusedByName) {
  const std::string finding = std::string(CRANIOPLAN_SOURCE_DIR) +
                              "/tests/fuzz/regressions/dicom/"
                              "crash-aa1995c66ed88178a0758a5d78cc7e04ccda612a";
  std::ifstream in(finding, std::ios::binary);
  ASSERT_TRUE(in) << finding;
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  bytes = bytes.substr(0, bytes.find("\n--cranioplan-slice--\n"));

  test::TempDir dir;
  Volume v;
  v.dims = {16, 16, 6};
  v.directions = Eigen::Vector3d(1.0, 1.0, 2.0).asDiagonal();
  v.data.assign(v.size(), 100.0f);
  test::write_dicom_series(v, dir.path("series"), {});
  const std::string bad = dir.path("series") + "/zz-bad.dcm";
  std::ofstream(bad, std::ios::binary) << bytes;

  const std::string m = message_of([&] { read_volume(dir.path("series")); });
  EXPECT_EQ(m.rfind(bad + ": ", 0), 0u) << m;
  EXPECT_NE(m.find("aborted (SIGABRT)"), std::string::npos) << m;
  EXPECT_NE(message_of([&] { list_dicom_series(dir.path("series")); }).find("zz-bad.dcm"),
            std::string::npos);

  std::filesystem::remove(bad);
  const Volume r = read_volume(dir.path("series"));
  EXPECT_EQ(r.dims, v.dims);
  EXPECT_EQ(r.data, v.data);
  EXPECT_EQ(list_dicom_series(dir.path("series")).size(), 1u);
}

}  // namespace
}  // namespace cranioplan
