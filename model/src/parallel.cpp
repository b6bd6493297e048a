#include "cranioplan/model/parallel.h"

#include <atomic>
#include <cstdlib>

namespace cranioplan {
namespace {

std::atomic<int> g_count{0};

int default_count() {
  if (const char* env = std::getenv("CRANIOPLAN_THREADS")) {
    const int n = std::atoi(env);
    if (n >= 1) return n;
  }
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

}  // namespace

int thread_count() {
  const int set = g_count.load();
  return set > 0 ? set : default_count();
}

void set_thread_count(int count) { g_count.store(std::max(0, count)); }

}  // namespace cranioplan
