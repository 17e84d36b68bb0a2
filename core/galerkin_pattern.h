#pragma once
// The pattern of a Galerkin product Pᵀ A P: the symbolic half of a product whose values are
// computed later on that pattern. The multigrid's coarse operators (solvers/galerkin.h,
// distributed/rank_multigrid.cpp) and the surface hierarchy's colourings of them
// (bases/surface_hierarchy.cpp) read it; it lives in core so that both layers share one kernel.

#include "core/sparse.h"

namespace mcf {

/// The pattern of the Galerkin product Pᵀ A P of a fine pattern A (square, compressed, symmetric:
/// the result's rows are read off its columns) and a prolongation P (fine x coarse, compressed):
/// entry (I, J) wherever P(i, I) A(i, j) P(j, J) is stored for some i, j (stored zeros count:
/// nothing cancels). The result is compressed and symmetric, each column's row indices ascending,
/// its values zero: the pattern of Eigen's SparseMatrix(Pᵀ) * A * P with positive values.
/// Two set products as the numeric product takes them, Pᵀ A and then (Pᵀ A) P, in time linear in
/// their terms, in parallel over fixed chunks of columns, and one counting pass that sorts the
/// symmetric result (a sort per column, or the product A P first, does more work): the same arrays
/// for any number of threads.
SparseMatrix galerkin_pattern(const SparseMatrix& P, const SparseMatrix& A);

}  // namespace mcf
