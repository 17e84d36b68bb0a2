#pragma once
// The multigrid's sparse products on a precomputed pattern (header solvers/multigrid.h, "Layout
// and cost"): the pattern of the Galerkin operator A_c = Pᵀ A P is built once per hierarchy
// (core/galerkin_pattern.h) with the positions of its transposed entries (transpose_positions),
// and its values are recomputed on that pattern whenever A's values change (galerkin_values).
//
// Inputs are compressed column-major matrices (SparseMatrix); the outputs' row indices are sorted.
// Determinism: every output entry is computed by one task in a fixed order, so the values are
// bitwise the same for any number of threads.
//
// Internal to the multigrid solver (namespace multigrid_detail); not part of the solvers'
// interface.

#include "core/sparse.h"
#include "solvers/csc_view.h"

#include <tbb/enumerable_thread_specific.h>

#include <cstdint>
#include <vector>

namespace mcf::multigrid_detail {

/// Positions of transposed entries of a matrix C with a symmetric, sorted pattern, to symmetrize
/// the computed values exactly: entry e = (i, J) -> position of (J, i) (-1 if absent).
std::vector<int> transpose_positions(const SparseMatrix& C);

/// Thread-local dense accumulators of galerkin_values (each resized to the fine level's size when
/// smaller; all zero between columns).
using Spa = tbb::enumerable_thread_specific<std::vector<double>>;

/// The visits of galerkin_values laid out once per pattern. Per coarse column J, in visit order
/// (column_order): the distinct fine rows of A P e_J numbered locally in order of first touch,
/// the local slot of every scatter term A(i, t) P(t, J), and for every upper entry (I <= J) the
/// dot-product terms P(q, I) v_q whose row q lies in that support (the others multiply a zero and
/// are left out: on the surface hierarchy more than half of them), each as its place in P's
/// column I and its slot. With a plan, galerkin_values accumulates each column in a buffer of a
/// few dozen entries (in L1) instead of a dense vector of the fine level's size, and walks no
/// fine-sized state to clear it: the same nonzero terms in the same order, hence the same values
/// bit for bit (but for the sign of an entry that sums to zero).
/// Empty (no plan) when a column's support does not fit 16-bit slots, a column of P has more than
/// 255 entries, or the plan would take more bytes than A itself (then galerkin_values keeps its
/// dense accumulator).
struct GalerkinPlan {
  std::vector<std::int64_t> scatter_start, dot_start, entry_start;  // per visited column (+1)
  std::vector<std::uint16_t> scatter_slot;  // per scatter term, in visit order
  std::vector<std::uint16_t> dot_slot;      // per kept dot-product term: its slot
  std::vector<std::uint8_t> dot_place;      // ... and its place in P's column I
  std::vector<std::uint8_t> dot_count;      // per upper entry: its kept terms
  std::vector<std::uint16_t> support;       // per visited column: its fine rows
  int max_support = 0;
  bool empty() const { return support.empty(); }
  std::size_t bytes() const {
    return 8 * (scatter_start.size() + dot_start.size() + entry_start.size()) +
           2 * (scatter_slot.size() + dot_slot.size() + support.size()) + dot_place.size() +
           dot_count.size();
  }
};

/// The plan of galerkin_values(A, P, C, ..., column_order) for A's, P's and C's patterns (C
/// sorted, as galerkin_pattern makes it). Parallel over columns; deterministic.
GalerkinPlan galerkin_plan(const Csc& A, const SparseMatrix& Pm, const SparseMatrix& Cm,
                           const std::vector<int>& column_order);

/// Values of the Galerkin operator A_c = Pᵀ A P on its precomputed (sorted, symmetric) pattern.
/// Per coarse column J, v = A P e_J is accumulated in a thread-local dense vector, and each entry
/// (I, J) with I <= J is the sparse dot product P e_I · v, written to (I, J) and to its mirror
/// (J, I): A_c is exactly symmetric, the intermediate A P is never stored, and only half of the
/// dot products are formed. Every entry is computed by one task in a fixed order: deterministic.
/// Columns are visited in `column_order` (internal column of the caller's column jj; empty:
/// identity), i.e. in grid order, so consecutive columns share most of their fine support and
/// their accumulators stay in cache (a colour-major visit is slower:
/// data/notes/implementation-choices.md).
/// A is a view (its values may be one term's, on the level's pattern); the values are written to
/// `Cval`, on Cm's pattern (Cm's own values when Cval is Cm.valuePtr()).
/// With a non-empty `plan` (galerkin_plan of the same patterns and column_order), the columns
/// accumulate in the plan's local slots; the values are those without it, bit for bit.
void galerkin_values(const Csc& A, const SparseMatrix& Pm, const SparseMatrix& Cm, double* Cval,
                     const std::vector<int>& transpose_pos, const std::vector<int>& column_order,
                     Spa& spa, const GalerkinPlan* plan = nullptr);

}  // namespace mcf::multigrid_detail
