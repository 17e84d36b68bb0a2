#pragma once
// The multigrid's sparse products on a precomputed pattern (header solvers/multigrid.h, "Layout
// and cost"): the pattern of the Galerkin operator A_c = Pᵀ A P, built once per hierarchy
// (symbolic_product, transpose_positions), and its values, recomputed on that pattern whenever A's
// values change (galerkin_values).
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

#include <vector>

namespace mcf::multigrid_detail {

/// Pattern of X * Y (sorted row indices, zero values). Parallel over the columns of Y.
SparseMatrix symbolic_product(const SparseMatrix& Xm, const SparseMatrix& Ym);

/// Positions of transposed entries of a matrix C with a symmetric, sorted pattern, to symmetrize
/// the computed values exactly: entry e = (i, J) -> position of (J, i) (-1 if absent).
std::vector<int> transpose_positions(const SparseMatrix& C);

/// Thread-local dense accumulators of galerkin_values (each resized to the fine level's size when
/// smaller; all zero between columns).
using Spa = tbb::enumerable_thread_specific<std::vector<double>>;

/// Values of the Galerkin operator A_c = Pᵀ A P on its precomputed (sorted, symmetric) pattern.
/// Per coarse column J, v = A P e_J is accumulated in a thread-local dense vector, and each entry
/// (I, J) with I <= J is the sparse dot product P e_I · v, written to (I, J) and to its mirror
/// (J, I): A_c is exactly symmetric, the intermediate A P is never stored, and only half of the
/// dot products are formed. Every entry is computed by one task in a fixed order: deterministic.
/// Columns are visited in `column_order` (internal column of the caller's column jj; empty:
/// identity), i.e. in grid order, so consecutive columns share most of their fine support and
/// their accumulators stay in cache (a colour-major visit is slower: docs/benchmarks.md,
/// "Measurements behind implementation choices").
/// A is a view (its values may be one term's, on the level's pattern); the values are written to
/// `Cval`, on Cm's pattern (Cm's own values when Cval is Cm.valuePtr()).
void galerkin_values(const Csc& A, const SparseMatrix& Pm, const SparseMatrix& Cm, double* Cval,
                     const std::vector<int>& transpose_pos, const std::vector<int>& column_order,
                     Spa& spa);

}  // namespace mcf::multigrid_detail
