// The pattern of a Galerkin product (core/galerkin_pattern.h) against the brute-force dense
// product Pᵀ A P of the operands' patterns, on small random sparse matrices (rows and columns left
// empty, stored zeros, a dense column, unsorted columns of A): the same entries, each column's row
// indices strictly ascending, zero values, and the same arrays on 1 and 2 threads.

#include "core/galerkin_pattern.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <Eigen/Dense>

#include <algorithm>
#include <functional>
#include <random>
#include <vector>

namespace mcf {
namespace {

/// A random m x n matrix with about `density` m n entries, a tenth of them stored zeros, and
/// column `dense_column` (if any) full.
SparseMatrix random_sparse(int m, int n, double density, unsigned seed, int dense_column = -1) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Eigen::Triplet<double>> t;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < m; ++i)
      if (j == dense_column || u(rng) < density) t.emplace_back(i, j, u(rng) < 0.1 ? 0.0 : u(rng));
  SparseMatrix M(m, n);
  M.setFromTriplets(t.begin(), t.end());
  M.makeCompressed();
  return M;
}

/// A random symmetric pattern on n functions with about `density` n² entries, the diagonal's
/// included where `diagonal`.
SparseMatrix random_symmetric(int n, double density, unsigned seed, bool diagonal) {
  const SparseMatrix L = random_sparse(n, n, density / 2, seed);
  SparseMatrix A = SparseMatrix(L + SparseMatrix(L.transpose()));
  if (diagonal) {
    SparseMatrix I(n, n);
    I.setIdentity();
    A = SparseMatrix(A + I);
  }
  A.makeCompressed();
  return A;
}

/// The stored entries of M as ones (stored zeros included), densely.
Eigen::MatrixXd ones_of(const SparseMatrix& M) {
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(M.rows(), M.cols());
  for (int j = 0; j < M.outerSize(); ++j)
    for (SparseMatrix::InnerIterator it(M, j); it; ++it) D(it.row(), j) = 1.0;
  return D;
}

/// C has exactly the entries where the dense product of the operands' patterns is nonzero (the
/// patterns' entries are ones, so nothing cancels), compressed, with each column's row indices
/// strictly ascending and zero values.
void expect_pattern_of(const SparseMatrix& C, const Eigen::MatrixXd& product) {
  ASSERT_TRUE(C.isCompressed());
  ASSERT_EQ(C.rows(), product.rows());
  ASSERT_EQ(C.cols(), product.cols());
  for (int j = 0; j < C.outerSize(); ++j) {
    const int* begin = C.innerIndexPtr() + C.outerIndexPtr()[j];
    const int* end = C.innerIndexPtr() + C.outerIndexPtr()[j + 1];
    EXPECT_TRUE(std::adjacent_find(begin, end, std::greater_equal<int>()) == end)
        << "column " << j << " is not strictly ascending";
  }
  const Eigen::MatrixXd expected = (product.array() > 0.0).cast<double>().matrix();
  EXPECT_TRUE(ones_of(C) == expected);
  for (Eigen::Index p = 0; p < C.nonZeros(); ++p) ASSERT_EQ(C.valuePtr()[p], 0.0);
}

bool same_arrays(const SparseMatrix& a, const SparseMatrix& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() && a.nonZeros() == b.nonZeros() &&
         std::equal(a.outerIndexPtr(), a.outerIndexPtr() + a.cols() + 1, b.outerIndexPtr()) &&
         std::equal(a.innerIndexPtr(), a.innerIndexPtr() + a.nonZeros(), b.innerIndexPtr());
}

TEST(GalerkinPattern, IsTheBruteForceDenseProductsPattern) {
  // 2200 fine and 1100 coarse functions: more than one chunk of columns in both set products.
  for (unsigned seed : {1u, 2u, 3u}) {
    const SparseMatrix A = random_symmetric(2200, 0.003, seed, seed != 2);
    const SparseMatrix P = random_sparse(2200, 1100, 0.0011, seed + 10, 17);
    const Eigen::MatrixXd product = ones_of(P).transpose() * ones_of(A) * ones_of(P);
    const SparseMatrix C = galerkin_pattern(P, A);
    expect_pattern_of(C, product);
    const SparseMatrix serial = [&] {
      tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
      return galerkin_pattern(P, A);
    }();
    EXPECT_TRUE(same_arrays(serial, C)) << "seed " << seed;
  }
}

TEST(GalerkinPattern, ReadsColumnsOfAInAnyOrder) {
  // The multigrid's finest matrix stores each column's diagonal last: the pattern does not depend
  // on the order of A's row indices within a column.
  const SparseMatrix A = random_symmetric(400, 0.02, 4, true);
  const SparseMatrix P = random_sparse(400, 90, 0.02, 5);
  SparseMatrix reversed = A;
  for (int j = 0; j < reversed.outerSize(); ++j)
    std::reverse(reversed.innerIndexPtr() + reversed.outerIndexPtr()[j],
                 reversed.innerIndexPtr() + reversed.outerIndexPtr()[j + 1]);
  const SparseMatrix C = galerkin_pattern(P, A);
  expect_pattern_of(C, ones_of(P).transpose() * ones_of(A) * ones_of(P));
  EXPECT_TRUE(same_arrays(galerkin_pattern(P, reversed), C));
}

TEST(GalerkinPattern, EmptyOperands) {
  const SparseMatrix A(6, 6), P(6, 3);
  const SparseMatrix C = galerkin_pattern(P, A);
  EXPECT_EQ(C.rows(), 3);
  EXPECT_EQ(C.cols(), 3);
  EXPECT_EQ(C.nonZeros(), 0);
  EXPECT_TRUE(C.isCompressed());
}

}  // namespace
}  // namespace mcf
