// The programs' first start (cranioplan, cranioplan-cli): sets malloc's tunables (huge pages,
// one arena: huge_pages.h) and starts the program itself, ../libexec/cranioplan/NAME from
// where this file lies, with the same arguments. Its libraries (VTK, Qt) are then loaded once:
// a program started directly loads them, sets the tunables and starts itself again (what that
// costs: docs/decisions/0030-memory-huge-pages-one-arena-no-copies.md). Links nothing but the
// C++ runtime.
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstring>
#include <string>

#include "cranioplan/algorithms/geometry/huge_pages.h"

#ifndef CRANIOPLAN_PROGRAM
#error "CRANIOPLAN_PROGRAM names the program this launcher starts"
#endif

int main(int, char** argv) {
  char self[PATH_MAX];
  const ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
  if (n <= 0) {
    std::fprintf(stderr, "%s: error: cannot tell where this program lies (/proc/self/exe: %s)\n",
                 argv[0], std::strerror(errno));
    return 1;
  }
  self[n] = '\0';
  std::string program(self);
  program.erase(program.rfind('/') + 1);
  program += "../libexec/cranioplan/" CRANIOPLAN_PROGRAM;
  cranioplan::ask_for_huge_pages();
  execv(program.c_str(), argv);
  std::fprintf(stderr, "%s: error: cannot start %s: %s (is the installation complete?)\n", argv[0],
               program.c_str(), std::strerror(errno));
  return 1;
}
