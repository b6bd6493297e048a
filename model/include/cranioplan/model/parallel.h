#pragma once
// Loops over independent items on several threads. Every use writes each item's result to its
// own place and reduces in item order afterwards, so results never depend on the number of
// threads (tested: the same implant bytes with 1 and 2 threads).
#include <algorithm>
#include <cstddef>
#include <future>
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

/// How a task that may run beside the caller's work is launched: on a thread of its own when
/// more than one thread is allowed, else when its result is asked for, on the caller's thread.
inline std::launch beside() {
  return thread_count() > 1 ? std::launch::async : std::launch::deferred;
}

/// Sorts [first, last) by `less`: two halves on two threads (when the count allows), then
/// merged. The same sequence as std::sort wherever elements that compare equal are alike (keys,
/// positions that become one vertex); otherwise equal elements may come in another order.
template <class It, class Less>
void parallel_sort(It first, It last, Less less) {
  const size_t n = static_cast<size_t>(last - first);
  const It middle = first + static_cast<std::ptrdiff_t>(n / 2);
  parallel_for(
      2,
      [&](size_t begin, size_t end) {
        for (size_t half = begin; half < end; ++half)
          std::sort(half == 0 ? first : middle, half == 0 ? middle : last, less);
      },
      n >= 50000 ? 1 : 2);
  std::inplace_merge(first, middle, last, less);
}

}  // namespace cranioplan
