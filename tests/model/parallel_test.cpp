#include "cranioplan/model/parallel.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <functional>
#include <random>

#include "cranioplan/algorithms/geometry/huge_pages.h"
#include "cranioplan/algorithms/io/write_mesh.h"
#include "cranioplan/algorithms/planning/autoplan.h"
#include "support/synthetic.h"

namespace cranioplan {
namespace {

// Restores the default thread count when a test ends.
struct ThreadCount {
  explicit ThreadCount(int n) { set_thread_count(n); }
  ~ThreadCount() { set_thread_count(0); }
};

// The tunables the programs start again with: added to the user's own tunables, never twice,
// each not at all when the user sets it, and none when the user turns them off.
TEST(HugePages, TheTunablesAreAddedOnceAndTheUsersChoiceKept) {
  const std::string ours = "glibc.malloc.hugetlb=1:glibc.malloc.arena_max=1";
  EXPECT_EQ(huge_page_tunables(nullptr, nullptr), ours);
  EXPECT_EQ(huge_page_tunables("", nullptr), ours);
  EXPECT_EQ(huge_page_tunables("glibc.malloc.check=3", "1"), "glibc.malloc.check=3:" + ours);
  EXPECT_EQ(huge_page_tunables("glibc.malloc.hugetlb=1", nullptr),
            "glibc.malloc.hugetlb=1:glibc.malloc.arena_max=1");
  EXPECT_EQ(huge_page_tunables("glibc.malloc.check=3:glibc.malloc.hugetlb=0", nullptr),
            "glibc.malloc.check=3:glibc.malloc.hugetlb=0:glibc.malloc.arena_max=1");
  EXPECT_EQ(huge_page_tunables("glibc.malloc.arena_max=4", nullptr),
            "glibc.malloc.arena_max=4:glibc.malloc.hugetlb=1");
  EXPECT_FALSE(huge_page_tunables(ours.c_str(), nullptr));  // the second start
  EXPECT_FALSE(huge_page_tunables(nullptr, "0"));
}

TEST(Parallel, EveryItemIsVisitedOnceWhateverTheThreads) {
  for (int threads : {1, 2, 3, 8}) {
    const ThreadCount count(threads);
    EXPECT_EQ(thread_count(), threads);
    for (size_t n : {size_t{0}, size_t{1}, size_t{7}, size_t{1000}, size_t{100003}}) {
      std::vector<std::atomic<int>> seen(n);
      parallel_for(
          n,
          [&](size_t first, size_t last) {
            for (size_t i = first; i < last; ++i) ++seen[i];
          },
          1);
      for (size_t i = 0; i < n; ++i) ASSERT_EQ(seen[i].load(), 1) << n << " " << i;
    }
  }
  set_thread_count(0);
  EXPECT_GE(thread_count(), 1);
}

// Sorted in two halves and merged, keys come out as std::sort gives them, on one thread and on
// two, below and above the size where the halves go to two threads, duplicates included.
TEST(Parallel, ParallelSortGivesWhatStdSortGives) {
  std::mt19937_64 rng(11);
  for (size_t n : {size_t{0}, size_t{1}, size_t{7}, size_t{1000}, size_t{120001}})
    for (int threads : {1, 2}) {
      const ThreadCount count(threads);
      std::vector<unsigned long long> keys(n);
      for (auto& k : keys) k = rng() % (n / 3 + 1);  // many repeats
      std::vector<unsigned long long> expected = keys;
      std::sort(expected.begin(), expected.end());
      parallel_sort(keys.begin(), keys.end(), std::less<>());
      EXPECT_EQ(keys, expected) << n << " keys, " << threads << " threads";
    }
}

// The plan (plane, registrations, distance fields, the implant) is the same to the byte on one
// thread and on two.
TEST(Parallel, TheImplantIsTheSameOnOneThreadAndOnTwo) {
  const SkullMesh& skull = test::thick_head_defect().defective;
  std::string bytes[2];
  for (int threads : {1, 2}) {
    const ThreadCount count(threads);
    const AutoplanResult r = autoplan(skull, Landmarks{});
    ASSERT_TRUE(r.planned()) << r.message;
    bytes[threads - 1] = encode_mesh(r.implant.mesh, MeshFormat::BinarySTL);
  }
  EXPECT_EQ(bytes[0], bytes[1]);
}

}  // namespace
}  // namespace cranioplan
