// Sets in compressed rows (core/compressed_sets.h): gather_sets keeps each set's members as its
// body writes them, over several chunks of indices, the same arrays on 1 and 2 threads; and
// sort_symmetric_sets sorts the sets of a symmetric relation.

#include "core/compressed_sets.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <random>
#include <set>
#include <utility>
#include <vector>

namespace mcf {
namespace {

/// A random symmetric relation on n indices without self pairs, as sets (each in random order).
std::vector<std::vector<int>> random_relation(int n, int pairs, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> pick(0, n - 1);
  std::vector<std::set<int>> unique(static_cast<std::size_t>(n));
  for (int k = 0; k < pairs; ++k) {
    const int x = pick(rng), y = pick(rng);
    if (x == y) continue;
    unique[std::size_t(x)].insert(y);
    unique[std::size_t(y)].insert(x);
  }
  std::vector<std::vector<int>> sets(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    sets[std::size_t(i)].assign(unique[std::size_t(i)].begin(), unique[std::size_t(i)].end());
    std::shuffle(sets[std::size_t(i)].begin(), sets[std::size_t(i)].end(), rng);
  }
  return sets;
}

/// gather_sets of `sets`, each member written twice (the second time discarded by the mark).
std::pair<std::vector<int>, std::vector<int>> gathered(const std::vector<std::vector<int>>& sets) {
  const int n = int(sets.size());
  std::vector<int> start, member;
  gather_sets(
      n, n, [&](int i) { return 2 * int(sets[std::size_t(i)].size()); },
      [&](int i, int* mark, int* out) {
        int count = 0;
        for (int repeat = 0; repeat < 2; ++repeat)
          for (int x : sets[std::size_t(i)]) {
            out[count] = x;
            count += mark[x] != i;
            mark[x] = i;
          }
        return count;
      },
      start, member);
  return {start, member};
}

TEST(CompressedSets, GatherKeepsTheBodysMembersAndSortSortsASymmetricRelation) {
  // 5000 indices: five chunks of gather_sets.
  const std::vector<std::vector<int>> sets = random_relation(5000, 20000, 3);
  const auto [start, member] = gathered(sets);
  ASSERT_EQ(start.size(), sets.size() + 1);
  for (std::size_t i = 0; i < sets.size(); ++i)
    ASSERT_TRUE(std::equal(member.begin() + start[i], member.begin() + start[i + 1],
                           sets[i].begin(), sets[i].end()))
        << "set " << i;
  {
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    const auto serial = gathered(sets);
    EXPECT_EQ(serial.first, start);
    EXPECT_EQ(serial.second, member);
  }
  std::vector<int> sorted = member;
  sort_symmetric_sets(start, sorted);
  for (std::size_t i = 0; i < sets.size(); ++i) {
    std::vector<int> expected = sets[i];
    std::sort(expected.begin(), expected.end());
    ASSERT_TRUE(std::equal(sorted.begin() + start[i], sorted.begin() + start[i + 1],
                           expected.begin(), expected.end()))
        << "set " << i;
  }
}

}  // namespace
}  // namespace mcf
