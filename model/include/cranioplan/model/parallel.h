#pragma once
// Loops over independent items on several threads. Every use writes each item's result to its
// own place and reduces in item order afterwards, so results never depend on the number of
// threads (tested: the same implant bytes with 1 and 2 threads).
#include <algorithm>
#include <cstddef>
#include <thread>
#include <vector>

namespace cranioplan {

/// Threads parallel loops use: set_thread_count's, else CRANIOPLAN_THREADS (≥ 1), else the
/// machine's hardware threads.
int thread_count();
/// 0 goes back to the default.
void set_thread_count(int count);

/// Calls f(begin, end) on contiguous ranges covering [0, n), one range per thread (ranges of
/// at least `min_items`, fewer threads for small n); returns when all are done.
template <class F>
void parallel_for(size_t n, F&& f, size_t min_items = 256) {
  const size_t threads = std::min<size_t>(static_cast<size_t>(std::max(1, thread_count())),
                                          std::max<size_t>(1, n / std::max<size_t>(1, min_items)));
  if (threads <= 1) {
    if (n > 0) f(size_t{0}, n);
    return;
  }
  std::vector<std::thread> pool;
  pool.reserve(threads - 1);
  const size_t chunk = (n + threads - 1) / threads;
  for (size_t t = 1; t < threads; ++t) {
    const size_t begin = t * chunk, end = std::min(n, begin + chunk);
    if (begin < end) pool.emplace_back([&f, begin, end] { f(begin, end); });
  }
  f(size_t{0}, std::min(n, chunk));
  for (std::thread& t : pool) t.join();
}

}  // namespace cranioplan
