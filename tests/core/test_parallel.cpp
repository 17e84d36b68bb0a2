// The parallel loops of core/parallel.h: every index once, fixed chunks whatever the threads.

#include "core/parallel.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
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

// The sum is the chunks' values added in chunk order, whatever the thread count: against that
// serial sum, bit for bit, on values whose sum depends on the order of addition.
TEST(Parallel, SumOverChunksAddsTheChunksInOrder) {
  std::vector<double> v(100003);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = 1.0 / double(i + 1) * (i % 2 ? -1e8 : 1.0);
  auto chunk = [&](long b, long e) {
    double s = 0;
    for (long i = b; i < e; ++i) s += v[std::size_t(i)];
    return s;
  };
  double serial = 0;
  for (long b = 0; b < long(v.size()); b += 1000)
    serial += chunk(b, std::min(long(v.size()), b + 1000));
  double plain = 0;
  for (double x : v) plain += x;
  ASSERT_NE(serial, plain);  // the order matters for these values, so the check below can fail
  for (int threads : {1, 2, 4}) {
    tbb::global_control cap(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
    EXPECT_EQ(sum_over_chunks<double>(long(v.size()), 1000L, chunk), serial) << threads;
  }
  EXPECT_EQ(sum_over_chunks<double>(0L, 1000L, chunk), 0.0);
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
