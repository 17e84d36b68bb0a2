#pragma once
// The sparse-matrix vocabulary every layer above shares: bases assemble these matrices, solvers
// solve with them, flows hand them from one to the other. Compressed column-major storage with
// int indices throughout (what CHOLMOD and the multigrid kernels read directly).

#include <Eigen/SparseCore>

#include <vector>

namespace mcf {

using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
/// A read-only view of a compressed matrix stored elsewhere. Bases hand out mass() and stiffness()
/// as views so that the two can share one pattern's index arrays (every basis here assembles both
/// on the pattern of its function pairs): at depth 9 a second copy of the row indices is 94 MB.
using SparseView = Eigen::Map<const SparseMatrix>;
/// Any column-major sparse matrix stored elsewhere — a SparseMatrix or a SparseView — without a
/// copy. Functions that read a basis's matrices take this.
using SparseRef = Eigen::Ref<const SparseMatrix>;

/// The view of a compressed matrix (throws std::invalid_argument for an uncompressed one, whose
/// index arrays a view cannot describe).
SparseView view_of(const SparseMatrix& A);
/// The view of values on a square pattern given by its column starts (columns + 1) and row
/// indices; an empty pattern (no column starts) gives an empty matrix. Throws
/// std::invalid_argument when the arrays disagree on the number of nonzeros.
SparseView view_of(const std::vector<int>& outer, const std::vector<int>& inner,
                   const std::vector<double>& values);

/// Σ_j A_jj over the stored diagonal entries of a compressed matrix with sorted row indices.
double diagonal_sum(const SparseRef& A);

}  // namespace mcf
