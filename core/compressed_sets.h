#pragma once
// Sets of indices in compressed rows (set i's members are member[start[i] .. start[i + 1]), a
// sparsity pattern without values), built in parallel: the coarse graphs of the surface hierarchy
// (bases/surface_hierarchy.cpp) and the columns of a Galerkin pattern (core/galerkin_pattern.h).
// Both functions give the same arrays for any number of threads.

#include "core/parallel.h"

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <cstddef>
#include <vector>

namespace mcf {

/// Sets over [0, universe) for the indices [0, n), in compressed rows, unsorted: body(i, mark,
/// out) writes set i's members to out[0 ..) and returns their number, where bound(i) is at least
/// that number and mark[x] == i says x is already written (`mark` is the calling thread's, never
/// reset). Fixed chunks of indices, each written by one task, so the arrays are the same for any
/// thread count.
template <class Bound, class Body>
void gather_sets(int n, int universe, Bound&& bound, Body&& body, std::vector<int>& start,
                 std::vector<int>& member) {
  constexpr int chunk = 1024;
  const int chunks = (n + chunk - 1) / chunk;
  std::vector<std::vector<int>> members(static_cast<std::size_t>(chunks));
  start.assign(std::size_t(n) + 1, 0);
  tbb::enumerable_thread_specific<std::vector<int>> marks(
      [universe] { return std::vector<int>(std::size_t(universe), -1); });
  parallel_for_chunks(n, chunk, [&](int c, int begin, int end) {
    std::vector<int>& mark = marks.local();
    std::vector<int>& out = members[std::size_t(c)];
    for (int i = begin; i < end; ++i) {
      const std::size_t first = out.size();
      out.resize(first + std::size_t(bound(i)));
      const int count = body(i, mark.data(), out.data() + first);
      out.resize(first + std::size_t(count));
      start[std::size_t(i) + 1] = count;
    }
  });
  for (int i = 0; i < n; ++i) start[std::size_t(i) + 1] += start[std::size_t(i)];
  member.resize(std::size_t(start.back()));
  parallel_for_indices(chunks, 1, [&](int c) {
    std::copy(members[std::size_t(c)].begin(), members[std::size_t(c)].end(),
              member.begin() + start[std::size_t(c) * chunk]);
  });
}

/// Sorts the sets of a symmetric relation in compressed rows (x in set y exactly when y is in set
/// x): its transpose, taken by one counting pass over the sets in order, is the relation with each
/// set ascending (set x's members are the sets that hold x).
void sort_symmetric_sets(const std::vector<int>& start, std::vector<int>& member);

}  // namespace mcf
