#include "core/undirected_graph.h"

#include "core/parallel.h"

#include <algorithm>

namespace mcf {

void undirected_graph(int n, const std::vector<std::pair<int, int>>& pairs, std::vector<int>& start,
                      std::vector<int>& neighbour) {
  const auto N = std::size_t(n);
  // Every pair in both directions, bucketed by its first vertex (duplicates still in).
  std::vector<int> first(N + 1, 0);
  for (const auto& [a, b] : pairs)
    if (a != b) {
      ++first[std::size_t(a) + 1];
      ++first[std::size_t(b) + 1];
    }
  for (std::size_t v = 0; v < N; ++v) first[v + 1] += first[v];
  std::vector<int> all(static_cast<std::size_t>(first[N]));
  std::vector<int> fill(first.begin(), first.end() - 1);
  for (const auto& [a, b] : pairs)
    if (a != b) {
      all[std::size_t(fill[std::size_t(a)]++)] = b;
      all[std::size_t(fill[std::size_t(b)]++)] = a;
    }
  // Each bucket sorted and its duplicates dropped in place; then the buckets compacted.
  std::vector<int> kept(N + 1, 0);
  parallel_for_indices(N, 1024, [&](std::size_t v) {
    const auto b = all.begin() + first[v], e = all.begin() + first[v + 1];
    std::sort(b, e);
    kept[v + 1] = int(std::unique(b, e) - b);
  });
  for (std::size_t v = 0; v < N; ++v) kept[v + 1] += kept[v];
  neighbour.resize(std::size_t(kept[N]));
  parallel_for_indices(N, 1024, [&](std::size_t v) {
    std::copy_n(all.begin() + first[v], kept[v + 1] - kept[v], neighbour.begin() + kept[v]);
  });
  start = std::move(kept);
}

}  // namespace mcf
