#include "cranioplan/algorithms/geometry/huge_pages.h"

#include <unistd.h>

#include <cstdlib>
#include <utility>

namespace cranioplan {

namespace {
// Each with the value the programs ask for; a name the user's GLIBC_TUNABLES holds keeps the
// user's value.
constexpr std::pair<const char*, const char*> kTunables[] = {{"glibc.malloc.hugetlb", "1"},
                                                             {"glibc.malloc.arena_max", "1"}};
}  // namespace

std::optional<std::string> huge_page_tunables(const char* glibc_tunables,
                                              const char* cranioplan_huge_pages) {
  if (cranioplan_huge_pages && std::string(cranioplan_huge_pages) == "0") return std::nullopt;
  std::string tunables = glibc_tunables ? glibc_tunables : "";
  bool added = false;
  for (const auto& [name, value] : kTunables) {
    if (tunables.find(name) != std::string::npos) continue;
    tunables += (tunables.empty() ? "" : ":") + std::string(name) + "=" + value;
    added = true;
  }
  if (!added) return std::nullopt;
  return tunables;
}

bool ask_for_huge_pages() {
  const std::optional<std::string> tunables =
      huge_page_tunables(std::getenv("GLIBC_TUNABLES"), std::getenv("CRANIOPLAN_HUGE_PAGES"));
  return tunables && setenv("GLIBC_TUNABLES", tunables->c_str(), 1) == 0;
}

void start_with_huge_pages(char** argv) {
  if (!ask_for_huge_pages()) return;
  execv("/proc/self/exe", argv);
  // Not started again (no /proc, say): on as we are. The variable stays, and is harmless.
}

}  // namespace cranioplan
