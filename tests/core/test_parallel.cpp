// The parallel loops of core/parallel.h: every index once, fixed chunks whatever the threads.

#include "core/parallel.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <atomic>
#include <cstddef>
#include <mutex>
#include <set>
#include <tuple>
#include <vector>

namespace mcf {
namespace {

TEST(Parallel, EveryIndexIsVisitedOnce) {
  for (std::size_t n : {std::size_t(0), std::size_t(1), std::size_t(1000), std::size_t(100000)}) {
    std::vector<std::atomic<int>> visits(n);
    parallel_for_indices<std::size_t>(n, 64, [&](std::size_t i) { ++visits[i]; });
    for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(visits[i].load(), 1) << "n " << n << " i " << i;
  }
}

TEST(Parallel, ChunksAreFixedWhateverTheThreadCount) {
  using Chunk = std::tuple<long, long, long>;
  auto chunks_with = [](int threads) {
    tbb::global_control cap(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
    std::mutex m;
    std::set<Chunk> seen;
    parallel_for_chunks(10001L, 1000L, [&](long c, long b, long e) {
      std::lock_guard<std::mutex> lock(m);
      seen.emplace(c, b, e);
    });
    return seen;
  };
  const std::set<Chunk> one = chunks_with(1);
  ASSERT_EQ(one.size(), 11u);
  EXPECT_EQ(*one.begin(), Chunk(0, 0, 1000));
  EXPECT_EQ(*one.rbegin(), Chunk(10, 10000, 10001));  // the last chunk is cut at n
  EXPECT_EQ(chunks_with(4), one);
}

TEST(Parallel, RunnableThreadsAreCappedAtTheDefaultConcurrency) {
  const int all = tbb::info::default_concurrency();
  EXPECT_EQ(runnable_threads(0), all);
  EXPECT_EQ(runnable_threads(-1), all);
  EXPECT_EQ(runnable_threads(1), 1);
  EXPECT_EQ(runnable_threads(all + 7), all);
}

}  // namespace
}  // namespace mcf
