#pragma once
// The parallel loops every layer writes, on TBB. Each takes a body whose iterations write
// disjoint outputs and read nothing another iteration of the same loop writes: then how the
// range is split among threads cannot change the result, which stays bitwise the same for any
// thread count. (Reductions, whose order of summation would depend on the split, are written out
// where they are needed, over fixed chunks: parallel_for_chunks.)

#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstddef>

namespace mcf {

/// body(i) for every i in [0, n), in parallel over blocks of at least `grain` indices (TBB's
/// blocked_range with its default partitioner).
template <class Index, class Body>
void parallel_for_indices(Index n, std::size_t grain, Body&& body) {
  tbb::parallel_for(tbb::blocked_range<Index>(Index(0), n, grain),
                    [&](const tbb::blocked_range<Index>& r) {
                      for (Index i = r.begin(); i != r.end(); ++i) body(i);
                    });
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

/// The number of threads that work when `requested` are asked for (0 or less: all): TBB never
/// runs more than its default concurrency, whatever a global_control allows.
inline int runnable_threads(int requested) {
  const int available = tbb::info::default_concurrency();
  return requested > 0 ? std::min(requested, available) : available;
}

}  // namespace mcf
