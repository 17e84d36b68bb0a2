// The coarsest solve on interleaved blocks against Eigen's own SimplicialLDLT solve (the same
// factor, one column at a time) and against the matrix itself (the residual of what it returns).
#include "solvers/interleaved_ldlt.h"

#include "test_matrices.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace mcf {
namespace {

using multigrid_detail::copy_factor;
using multigrid_detail::InterleavedLdlt;
using multigrid_detail::solve_interleaved;

TEST(InterleavedLdlt, MatchesEigenSolveOnEveryColumnAndLeavesPaddingZero) {
  const int n = 700;
  const SparseMatrix A = test::graph_laplacian(n, 3, 0.05, 11);  // fill-in in its factor
  Eigen::SimplicialLDLT<SparseMatrix> ldlt(A);
  ASSERT_EQ(ldlt.info(), Eigen::Success);
  ASSERT_GT(ldlt.matrixL().nestedExpression().nonZeros(), A.nonZeros() / 2);  // real fill-in
  InterleavedLdlt f;
  copy_factor(ldlt, f);
  ASSERT_EQ(f.n(), n);
  // Seven columns in a stride of 8: two groups of four, the last column padding.
  const int k = 7;
  const std::size_t s = 8;
  const Eigen::MatrixXd B = test::random_rhs(n, k, 5);
  std::vector<double> b(std::size_t(n) * s, 0.0), x(std::size_t(n) * s, -1.0), work;
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < k; ++c) b[std::size_t(i) * s + std::size_t(c)] = B(i, c);
  solve_interleaved(f, b.data(), x.data(), s, work);
  Eigen::MatrixXd X(n, k);
  for (int i = 0; i < n; ++i) {
    for (int c = 0; c < k; ++c) X(i, c) = x[std::size_t(i) * s + std::size_t(c)];
    EXPECT_EQ(x[std::size_t(i) * s + 7], 0.0) << "padding of row " << i;
  }
  const Eigen::MatrixXd reference = ldlt.solve(B);
  for (int c = 0; c < k; ++c) {
    EXPECT_LE((X.col(c) - reference.col(c)).norm(), 1e-12 * reference.col(c).norm()) << c;
    EXPECT_LE((A * X.col(c) - B.col(c)).norm(), 1e-10 * B.col(c).norm()) << c;
  }
}

TEST(InterleavedLdlt, FollowsTheFactorOfEachNewMatrix) {
  // copy_factor reuses the struct's memory: a second matrix on another pattern and size must not
  // see the first's arrays.
  InterleavedLdlt f;
  std::vector<double> work;
  for (const int n : {300, 120}) {
    const SparseMatrix A = test::graph_laplacian(n, 3, 0.05, unsigned(n));
    Eigen::SimplicialLDLT<SparseMatrix> ldlt(A);
    copy_factor(ldlt, f);
    std::vector<double> b(std::size_t(n) * 4, 0.0), x(std::size_t(n) * 4);
    Eigen::VectorXd B(n);
    for (int i = 0; i < n; ++i) B(i) = b[std::size_t(i) * 4] = std::sin(0.1 * i) + 0.5;
    solve_interleaved(f, b.data(), x.data(), 4, work);
    Eigen::VectorXd X(n);
    for (int i = 0; i < n; ++i) X(i) = x[std::size_t(i) * 4];
    EXPECT_LE((A * X - B).norm(), 1e-10 * B.norm()) << n;
  }
}

}  // namespace
}  // namespace mcf
