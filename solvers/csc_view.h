#pragma once
// What the multigrid's parts (smoother, Galerkin product, level ordering, cycle) share: a raw view
// of a compressed column-major matrix, whose arrays the kernels index directly, and the row loop
// they run in parallel. Internal to solvers/multigrid*.cpp, solvers/smoother.*, solvers/galerkin.*
// and solvers/level_ordering.*; not part of the solvers' interface.
//
// Determinism: for_rows only splits [0, n) among threads; with a body that writes disjoint
// outputs and reads nothing the same loop writes, its result does not depend on the split.

#include "core/sparse.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

namespace mcf::multigrid_detail {

constexpr int kGrain = 4096;        // rows per TBB task, at most (fixed blocks: simple_partitioner)
constexpr int kSerialBelow = 2048;  // loops shorter than this run serially (same result)

/// Runs f(begin, end) over [0, n), in parallel when n is large enough. Every kernel writes
/// disjoint outputs and reads nothing that the same loop writes, so the split is irrelevant.
template <class F>
void for_rows(int n, F&& f) {
  if (n < kSerialBelow) {
    f(0, n);
    return;
  }
  // Split points fixed by n and the grain (core/parallel.h: a vectorized block and its scalar
  // remainder may round differently, so where a block ends must not move with the threads).
  tbb::parallel_for(
      tbb::blocked_range<int>(0, n, kGrain),
      [&](const tbb::blocked_range<int>& r) { f(r.begin(), r.end()); }, tbb::simple_partitioner());
}

/// Raw view of a compressed column-major matrix.
struct Csc {
  int rows = 0, cols = 0;
  const int* outer = nullptr;
  const int* inner = nullptr;
  const double* val = nullptr;
  explicit Csc(const SparseRef& m)
      : rows(int(m.rows())),
        cols(int(m.cols())),
        outer(m.outerIndexPtr()),
        inner(m.innerIndexPtr()),
        val(m.valuePtr()) {}
};

}  // namespace mcf::multigrid_detail
