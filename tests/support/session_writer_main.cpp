// Helper for the crash-recovery test: plans with many small commands, autosaving each, and says
// "done N" on stdout after command N has returned. The test kills it with SIGKILL at random.
#include <cstdio>
#include <string>

#include "cranioplan/sessions/session.h"

int main(int argc, char** argv) {
  using namespace cranioplan;
  if (argc != 4) {
    std::fprintf(stderr, "usage: %s SKULL.stl AUTOSAVE COMMANDS\n", argv[0]);
    return 2;
  }
  const int count = std::stoi(argv[3]);
  Session session(SessionInfo{"crash-test", "writer", ""});
  session.set_autosave_path(argv[2]);
  auto push = [&](Command c, int n) {
    if (!session.push(std::move(c)).accepted) return false;
    std::printf("done %d\n", n);
    std::fflush(stdout);
    return true;
  };
  if (!push(commands::load_skull(argv[1]), 1)) return 1;
  for (int i = 2; i <= count; ++i) {
    // Notes, landmarks and undo/redo: cheap commands of every journal event kind.
    bool ok = true;
    if (i % 7 == 0) {
      ok = session.undo();
      if (ok) {
        std::printf("done %d\n", i);
        std::fflush(stdout);
      }
    } else if (i % 7 == 1 && session.can_redo()) {
      ok = session.redo();
      if (ok) {
        std::printf("done %d\n", i);
        std::fflush(stdout);
      }
    } else {
      ok = push(commands::note("note " + std::to_string(i)), i);
    }
    if (!ok) return 1;
  }
  return 0;
}
