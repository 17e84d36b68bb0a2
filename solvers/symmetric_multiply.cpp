#include "solvers/symmetric_multiply.h"

#include "core/parallel.h"

#include <algorithm>
#include <stdexcept>

namespace mcf {
namespace {

using Eigen::Index;

// The value of entry p: the matrix's own, or a sum of matrices on one pattern formed on the fly.
struct Values {
  const double* val;
  double operator()(int p) const { return val[p]; }
};
struct SumValues {
  const MatrixSum& sum;
  double operator()(int p) const { return sum.entry(p); }
};

// Rows [b, e) for a compile-time number of columns K: one pass over each row's entries feeds all
// K sums (the flows' x, y, z).
template <int K, class V>
void rows_fixed(const int* outer, const int* inner, const V& value, const double* X, double* Y,
                Index n, Index b, Index e) {
  for (Index i = b; i < e; ++i) {
    double s[K] = {};
    for (int p = outer[i]; p < outer[i + 1]; ++p) {
      const double v = value(p);
      const double* x = X + inner[p];
      for (int c = 0; c < K; ++c) s[c] += v * x[c * n];
    }
    for (int c = 0; c < K; ++c) Y[c * n + i] = s[c];
  }
}

template <class V>
void rows_any(const int* outer, const int* inner, const V& value, const double* X, double* Y,
              Index n, Index k, Index b, Index e) {
  for (Index c = 0; c < k; ++c)
    for (Index i = b; i < e; ++i) {
      double s = 0.0;
      for (int p = outer[i]; p < outer[i + 1]; ++p) s += value(p) * X[c * n + inner[p]];
      Y[c * n + i] = s;
    }
}

template <class V>
void multiply(const SparseRef& A, const V& value, const double* X, Index k, double* Y) {
  if (A.rows() != A.cols())
    throw std::invalid_argument("symmetric_multiply: the matrix is not square");
  if (!A.isCompressed())
    throw std::invalid_argument("symmetric_multiply: the matrix is not compressed");
  const Index n = A.rows();
  const int* outer = A.outerIndexPtr();
  const int* inner = A.innerIndexPtr();
  // Fixed chunks: the partition does not depend on the thread count (no sums cross a chunk
  // anyway, but equal chunks balance the rows).
  constexpr Index kChunk = 4096;
  parallel_for_chunks(n, kChunk, [&](Index, Index b, Index e) {
    switch (k) {
      case 1:
        rows_fixed<1>(outer, inner, value, X, Y, n, b, e);
        break;
      case 2:
        rows_fixed<2>(outer, inner, value, X, Y, n, b, e);
        break;
      case 3:
        rows_fixed<3>(outer, inner, value, X, Y, n, b, e);
        break;
      case 4:
        rows_fixed<4>(outer, inner, value, X, Y, n, b, e);
        break;
      case 6:
        rows_fixed<6>(outer, inner, value, X, Y, n, b, e);
        break;
      default:
        rows_any(outer, inner, value, X, Y, n, k, b, e);
        break;
    }
  });
}

}  // namespace

void symmetric_multiply(const SparseRef& A, const double* X, Index k, double* Y) {
  multiply(A, Values{A.valuePtr()}, X, k, Y);
}

void symmetric_multiply(const MatrixSum& A, const double* X, Index k, double* Y) {
  if (!summable(A)) throw std::invalid_argument("symmetric_multiply: the terms differ in pattern");
  multiply(A.M, SumValues{A}, X, k, Y);
}

}  // namespace mcf
