#pragma once
// Y = A X for a symmetric sparse A, in parallel and deterministically.
//
// Why not Eigen's `A * X`: for column-major storage Eigen scatters column j times x_j into Y,
// which is serial (data/notes/implementation-choices.md).
// Because A is symmetric, column i of the column-major storage is row i, so every output entry is
// an independent gather: parallel without write conflicts, each sum in the entry order whatever
// the thread count. The flows use it for M X and K X, PCG for its products.

#include "solvers/linear_solver.h"

#include <Eigen/Core>

#include <stdexcept>

namespace mcf {

/// Y (n x k, column-major, leading dimension n) = A X for symmetric A (n x n, both triangles
/// stored), X column-major n x k. Uses only A's storage, never its transpose: a non-symmetric A
/// gives Aᵀ X.
void symmetric_multiply(const SparseRef& A, const double* X, Eigen::Index k, double* Y);

/// Y = (a M + b K [+ s S]) X for terms on one pattern (same_pattern; summable() is checked), in one
/// pass over the pattern with the entries formed by MatrixSum::entry: the sum is never stored.
void symmetric_multiply(const MatrixSum& A, const double* X, Eigen::Index k, double* Y);

inline Eigen::Index rows_of(const SparseRef& A) {
  return A.rows();
}
inline Eigen::Index rows_of(const MatrixSum& A) {
  return A.M.rows();
}

/// Y = A X for column-major dense Eigen matrices (MatrixXd, the flows' n x 3 coefficients, an
/// Eigen::Ref); Y must be resizable.
template <class Matrix, class In, class Out>
void symmetric_multiply(const Matrix& A, const In& X, Out& Y) {
  static_assert(!In::IsRowMajor && !Out::IsRowMajor,
                "symmetric_multiply: column-major dense matrices only");
  const Eigen::Index n = rows_of(A);
  if (X.rows() != n) throw std::invalid_argument("symmetric_multiply: sizes do not match");
  Y.resize(n, X.cols());
  if (X.outerStride() == X.rows()) {
    symmetric_multiply(A, X.data(), X.cols(), Y.data());
  } else {  // columns apart (a block of a larger matrix): the kernel reads one leading dimension
    const Eigen::MatrixXd contiguous = X;
    symmetric_multiply(A, contiguous.data(), contiguous.cols(), Y.data());
  }
}

template <class Matrix, class Dense>
Dense symmetric_multiply(const Matrix& A, const Dense& X) {
  Dense Y;
  symmetric_multiply(A, X, Y);
  return Y;
}

}  // namespace mcf
