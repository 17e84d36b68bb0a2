#pragma once
// The parallel loops every layer writes, on TBB. Each takes a body whose iterations write
// disjoint outputs and read nothing another iteration of the same loop writes, and splits the
// range at points that depend on its length and grain only (TBB's simple_partitioner halves a
// range until it is at most the grain; the auto partitioner splits where threads steal work).
// Fixed split points matter even without a reduction: the compiler vectorizes the loop over a
// block and finishes its remainder in scalar code, and the two may round a face's area or a
// row's sum differently (a fused multiply-add in one and not the other), so a split that moved
// with the threads' timing changed the last bits of the results from run to run. With fixed
// splits the result is bitwise the same for any thread count. (Reductions are taken over fixed
// chunks: parallel_for_chunks, and sum_over_chunks for a plain sum of per-chunk values.)

#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include <algorithm>
#include <cstddef>
#include <vector>

namespace mcf {

/// body(i) for every i in [0, n), in parallel over blocks of at most `grain` indices whose
/// bounds depend on n and grain only (simple_partitioner).
template <class Index, class Body>
void parallel_for_indices(Index n, std::size_t grain, Body&& body) {
  tbb::parallel_for(
      tbb::blocked_range<Index>(Index(0), n, grain),
      [&](const tbb::blocked_range<Index>& r) {
        for (Index i = r.begin(); i != r.end(); ++i) body(i);
      },
      tbb::simple_partitioner());
}

/// body(chunk, begin, end) for the fixed chunks [c * size, min(n, (c + 1) * size)) of [0, n), in
/// parallel. The partition depends on n and size only, never on the thread count, so sums taken
/// per chunk and combined in chunk order are deterministic.
template <class Index, class Body>
void parallel_for_chunks(Index n, Index size, Body&& body) {
  const Index chunks = (n + size - 1) / size;
  tbb::parallel_for(tbb::blocked_range<Index>(0, chunks, 1),
                    [&](const tbb::blocked_range<Index>& r) {
                      for (Index c = r.begin(); c < r.end(); ++c)
                        body(c, c * size, std::min(n, (c + 1) * size));
                    });
}

/// Σ over the fixed chunks of [0, n) (parallel_for_chunks) of value(begin, end), the chunks' values
/// added in chunk order: the same bits for any thread count. T is zero-initialised by T{} and
/// added with +=.
template <class T, class Index, class Value>
T sum_over_chunks(Index n, Index size, Value&& value) {
  std::vector<T> partial(std::size_t((n + size - 1) / size));
  parallel_for_chunks(n, size,
                      [&](Index c, Index b, Index e) { partial[std::size_t(c)] = value(b, e); });
  T total{};
  for (const T& p : partial) total += p;
  return total;
}

/// The number of threads that work when `requested` are asked for (0 or less: all): TBB never
/// runs more than its default concurrency, whatever a global_control allows.
inline int runnable_threads(int requested) {
  const int available = tbb::info::default_concurrency();
  return requested > 0 ? std::min(requested, available) : available;
}

}  // namespace mcf
