// undirected_graph against the reference it replaces: every directed pair sorted, duplicates
// removed, on a random multigraph with repeated and reversed pairs and self loops.
#include "core/undirected_graph.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace mcf {
namespace {

TEST(UndirectedGraph, EqualsSortingEveryDirectedPair) {
  std::mt19937 rng(7);
  const int n = 5000;
  std::uniform_int_distribution<int> vertex(0, n - 1);
  std::vector<std::pair<int, int>> pairs;
  for (int k = 0; k < 40000; ++k) {
    const int a = vertex(rng), b = k % 7 == 0 ? a : (a + 1 + vertex(rng) % 12) % n;
    pairs.emplace_back(a, b);
    if (k % 3 == 0) pairs.emplace_back(b, a);  // given both ways
    if (k % 5 == 0) pairs.emplace_back(a, b);  // given twice
  }
  std::vector<std::pair<int, int>> both;
  for (const auto& [a, b] : pairs)
    if (a != b) {
      both.emplace_back(a, b);
      both.emplace_back(b, a);
    }
  std::sort(both.begin(), both.end());
  both.erase(std::unique(both.begin(), both.end()), both.end());
  std::vector<int> start, neighbour;
  undirected_graph(n, pairs, start, neighbour);
  ASSERT_EQ(start.size(), std::size_t(n) + 1);
  ASSERT_EQ(neighbour.size(), both.size());
  EXPECT_EQ(start.front(), 0);
  EXPECT_EQ(std::size_t(start.back()), both.size());
  for (int v = 0, k = 0; v < n; ++v)
    for (int p = start[std::size_t(v)]; p < start[std::size_t(v) + 1]; ++p, ++k) {
      ASSERT_EQ(both[std::size_t(k)].first, v);
      ASSERT_EQ(both[std::size_t(k)].second, neighbour[std::size_t(p)]);
    }
  // No pairs: n empty rows.
  undirected_graph(3, {}, start, neighbour);
  EXPECT_EQ(start, std::vector<int>(4, 0));
  EXPECT_TRUE(neighbour.empty());
}

}  // namespace
}  // namespace mcf
