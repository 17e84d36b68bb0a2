#pragma once
// The multigrid's Gauss-Seidel smoother (header solvers/multigrid.h, "Smoother matrix" and
// "Layout and cost", "Smoother ordering"): the row kernels that relax one row of an interleaved
// block, the compact rows (SmootherRows) they read, the set-up of those rows and of each level's
// diagonal positions, and the sweep that relaxes a whole level in its relaxation order.
//
// - gather_sub and gather_sub_compact subtract a run of a row's terms from two accumulators,
//   alternately, in the order of the stored entries; gs_row, gs_row_compact and gs_row_aligned
//   relax one row i (its four columns o..o+3 of x, in place) from b and the neighbours' current
//   iterates. Nothing in them depends on threads: a sweep's result is fixed to the bit by the
//   order in which its caller visits the rows.
// - The kernels are in this header, force-inlined, because the sweeps (gauss_seidel_sweep,
//   solvers/smoother.cpp) and the cycle's residual (solvers/multigrid_cycle.cpp) run at full speed
//   only with them inlined into their loops (below).
// - gauss_seidel_sweep visits a level's rows in the one serial order that relaxation_order()
//   lists (solvers/level_ordering.h), blocks of one parity in parallel, so its result is the same
//   for any number of threads.
// - The set-up functions (solvers/smoother.cpp) are deterministic: parallel loops that each write
//   disjoint entries.
//
// Internal to the multigrid solver (namespace multigrid_detail); not part of the solvers'
// interface.

#include "core/sparse.h"
#include "core/vec4.h"
#include "solvers/csc_view.h"
#include "solvers/level_ordering.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace mcf::multigrid_detail {

// The kernels below cost a few instructions per matrix entry and run at full speed only when
// inlined into their loops: out of line, the two accumulators passed by reference go through
// memory on every entry. GCC stopped inlining gather_sub and gather_sub_compact once they had a
// few more call sites (data/notes/implementation-choices.md), so they are forced.
#define MCF_KERNEL_INLINE inline __attribute__((always_inline))

// The kernels below hold four right-hand-side columns of one row in one vector (core/vec4.h).
using vec4::load4;
using vec4::splat;
using vec4::store4;
using vec4::v4;

// ---- kernels on interleaved buffers ---------------------------------------------------------
//
// Entry (i, c) of an n x k block lives at i*s + c, with the stride s = k rounded up to a multiple
// of 4 (padding columns are zero and stay zero): every kernel handles four columns of a row as one
// vector, columns o..o+3: one load of a neighbour's iterate instead of three, one vector multiply-
// add instead of three. A row's terms are summed alternately into two vector accumulators (even
// and odd positions of each run of entries), which halves the chain of dependent multiply-adds.
// That shortens the time per entry on cached data; on the finest levels the sweeps are bound by
// memory traffic instead (SmootherRows, relaxation blocks).

/// Σ_p val[p] x[inner[p]] over p in [begin, end), into acc0 (even p - begin) and acc1 (odd).
MCF_KERNEL_INLINE void gather_sub(const Csc& A, const double* x, std::size_t s, int o, int begin,
                                  int end, v4& acc0, v4& acc1) {
  int p = begin;
  for (; p + 1 < end; p += 2) {
    acc0 -= splat(A.val[p]) * load4(x + std::size_t(A.inner[p]) * s + o);
    acc1 -= splat(A.val[p + 1]) * load4(x + std::size_t(A.inner[p + 1]) * s + o);
  }
  if (p < end) acc0 -= splat(A.val[p]) * load4(x + std::size_t(A.inner[p]) * s + o);
}

/// One Gauss-Seidel update of row i (= column i of the symmetric CSC matrix), columns o..o+3.
/// diag_pos[i] is the position of the diagonal entry in column i (-1 if absent): the sum runs
/// over the entries before and after it, in index order, without a test per entry.
MCF_KERNEL_INLINE void gs_row(const Csc& A, const int* diag_pos, const double* inv_diag,
                              const double* b, double* x, std::size_t s, int o, int i) {
  const std::size_t ii = std::size_t(i) * s + o;
  v4 acc0 = load4(b + ii), acc1 = splat(0.0);
  const int dp = diag_pos[i];
  if (dp >= 0) {
    gather_sub(A, x, s, o, A.outer[i], dp, acc0, acc1);
    gather_sub(A, x, s, o, dp + 1, A.outer[i + 1], acc0, acc1);
  } else {
    gather_sub(A, x, s, o, A.outer[i], A.outer[i + 1], acc0, acc1);
  }
  store4(x + ii, (acc0 + acc1) * splat(inv_diag[i]));
}

/// A level's off-diagonal entries as the smoother reads them, each entry's column as (column -
/// row) in 16 bits. The sweeps stream the matrix ten times per level visit and are bound by its
/// bytes once the iterate stays in cache.
/// - Coarse levels: row by row in the internal numbering, the diagonal left out, the values in
///   single precision (6 bytes an entry instead of CSC's 12).
/// - Finest level (`aligned`): one offset per entry of the level's CSC matrix, whose columns store
///   their diagonal last (diagonal_last), so a row's off-diagonal entries are one run of the
///   matrix's own values: 10 bytes an entry, and the largest matrix is stored once (no copy of its
///   values beside it). Why not single precision here: a Gauss-Seidel update
///   x_i = (b_i - Σ a_ij x_j) / a_ii with rounded a_ij has the rounded system's solution as its
///   fixed point, so the finest level's sweeps would pull the iterate off A x = b (a test that
///   cycles to 1e-10 stalled at 2e-8); on a coarse level the sweeps only shape a correction of
///   the finest residual, which is exact, so the cycle still converges to the solution of A x = b.
/// Unused when some column lies farther than 16 bits from its row (the sweeps then read the CSC).
struct SmootherRows {
  bool aligned = false;              // finest level: offset[p] belongs to CSC entry p
  std::vector<int> start;            // coarse levels: row i's entries [start[i], start[i+1])
  std::vector<std::int16_t> offset;  // column - row
  std::vector<float> single;         // coarse levels' values
  bool empty() const { return !aligned && start.empty(); }
};

/// acc0/acc1 -= Σ_p val[p] x[i + offset[p]] over the compact entries [begin, end).
template <class V>
MCF_KERNEL_INLINE void gather_sub_compact(const std::int16_t* off, const V* val, const double* xi,
                                          std::size_t s, int begin, int end, v4& acc0, v4& acc1) {
  const std::ptrdiff_t st = std::ptrdiff_t(s);
  int p = begin;
  for (; p + 1 < end; p += 2) {
    acc0 -= splat(double(val[p])) * load4(xi + std::ptrdiff_t(off[p]) * st);
    acc1 -= splat(double(val[p + 1])) * load4(xi + std::ptrdiff_t(off[p + 1]) * st);
  }
  if (p < end) acc0 -= splat(double(val[p])) * load4(xi + std::ptrdiff_t(off[p]) * st);
}

/// gs_row on a coarse level's compact rows (values val: S.single).
template <class V>
MCF_KERNEL_INLINE void gs_row_compact(const SmootherRows& S, const V* val, const double* inv_diag,
                                      const double* b, double* x, std::size_t s, int o, int i) {
  const std::size_t ii = std::size_t(i) * s + o;
  v4 acc0 = load4(b + ii), acc1 = splat(0.0);
  gather_sub_compact(S.offset.data(), val, x + ii, s, S.start[std::size_t(i)],
                     S.start[std::size_t(i) + 1], acc0, acc1);
  store4(x + ii, (acc0 + acc1) * splat(inv_diag[i]));
}

/// gs_row on the finest level's aligned offsets: the row's off-diagonal entries are the run
/// before its diagonal (stored last), read from the matrix itself; bitwise what gs_row_compact
/// computes on a copy of them.
MCF_KERNEL_INLINE void gs_row_aligned(const Csc& A, const std::int16_t* off, const int* diag_pos,
                                      const double* inv_diag, const double* b, double* x,
                                      std::size_t s, int o, int i) {
  const std::size_t ii = std::size_t(i) * s + o;
  v4 acc0 = load4(b + ii), acc1 = splat(0.0);
  const int dp = diag_pos[i];
  gather_sub_compact(off, A.val, x + ii, s, A.outer[i], dp >= 0 ? dp : A.outer[i + 1], acc0, acc1);
  store4(x + ii, (acc0 + acc1) * splat(inv_diag[i]));
}

// ---- set-up -----------------------------------------------------------------------------

/// Position of the diagonal entry of each column of A (square, compressed), -1 if none.
std::vector<int> diagonal_positions(const SparseMatrix& A);

/// Moves each column's diagonal entry of A (the finest matrix) to the column's end (the other
/// entries keep their order) and returns where it was: the diagonal's place in each column (-1:
/// none; diag_rank).
std::vector<int> diagonal_last(SparseMatrix& A);

/// The compact rows' pattern (SmootherRows) of a coloured level's matrix A, or none (empty) when
/// an offset does not fit 16 bits: on the finest level one offset per CSC entry (aligned; its
/// values are the matrix's own), on coarse levels the off-diagonal entries only (diag_pos:
/// diagonal_positions(A)), with room for their single-precision values.
SmootherRows smoother_pattern(const SparseMatrix& A, const std::vector<int>& diag_pos, bool finest);

/// A coarse level's compact values from its matrix A (same order, diagonal skipped, rounded to
/// single precision). The finest level's sweeps read the matrix's own values.
void smoother_values(SmootherRows& S, const SparseMatrix& A, const std::vector<int>& diag_pos);

// ---- the sweep -------------------------------------------------------------------------------

/// One Gauss-Seidel sweep for A x = b on a level numbered by L (solvers/level_ordering.h), forward
/// (pre-smoothing) or reverse (post-smoothing), in the order relaxation_order(L, n, reverse) lists
/// (header solvers/multigrid.h, "Smoother ordering"): a coloured level block by block, colour by
/// colour; a level without colours block by block in row order. Blocks of one parity are relaxed
/// in parallel, which is exact because they never couple (find_blocks). Each row is relaxed by
/// gs_row_aligned on the finest level's aligned rows, gs_row_compact on a coarse level's compact
/// rows, gs_row on the CSC matrix where S is empty. A is the level's matrix (internal numbering),
/// S its smoother rows, diag_pos and inv_diag its diagonal's positions and inverses; b and x are
/// interleaved with row stride s (a multiple of 4), x updated in place.
void gauss_seidel_sweep(const LevelNumbering& L, const Csc& A, const SmootherRows& S,
                        const int* diag_pos, const double* inv_diag, const double* b, double* x,
                        std::size_t s, bool reverse);

}  // namespace mcf::multigrid_detail
