#include "cranioplan/algorithms/geometry/huge_pages.h"

#include <unistd.h>

#include <cstdlib>
#include <fstream>

namespace cranioplan {

namespace {
constexpr const char* kTunable = "glibc.malloc.hugetlb";
}

std::optional<std::string> huge_page_tunables(const char* glibc_tunables,
                                              const char* cranioplan_huge_pages) {
  if (cranioplan_huge_pages && std::string(cranioplan_huge_pages) == "0") return std::nullopt;
  const std::string present = glibc_tunables ? glibc_tunables : "";
  if (present.find(kTunable) != std::string::npos) return std::nullopt;
  return (present.empty() ? "" : present + ":") + kTunable + "=1";
}

bool ask_for_huge_pages() {
  const std::optional<std::string> tunables =
      huge_page_tunables(std::getenv("GLIBC_TUNABLES"), std::getenv("CRANIOPLAN_HUGE_PAGES"));
  if (!tunables) return false;
  // "always [madvise] never": malloc's advice is taken unless the kernel says never.
  std::ifstream thp("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string modes;
  if (!std::getline(thp, modes) || modes.find("[never]") != std::string::npos) return false;
  return setenv("GLIBC_TUNABLES", tunables->c_str(), 1) == 0;
}

void start_with_huge_pages(char** argv) {
  if (!ask_for_huge_pages()) return;
  execv("/proc/self/exe", argv);
  // Not started again (no /proc, say): on as we are. The variable stays, and is harmless.
}

}  // namespace cranioplan
