// The coarsest solve on interleaved blocks against Eigen's own SimplicialLDLT solve (the same
// factor, one column at a time) and against the matrix itself (the residual of what it returns).
#include "solvers/interleaved_ldlt.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace mcf {
namespace {

using multigrid_detail::copy_factor;
using multigrid_detail::InterleavedLdlt;
using multigrid_detail::solve_interleaved;

/// A graph Laplacian of a random sparse graph plus a positive diagonal: symmetric positive
/// definite, with fill-in in its factor.
SparseMatrix random_spd(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> col(0, n - 1), len(1, 5);
  std::uniform_real_distribution<double> w(0.1, 1.0);
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < n; ++i) {
    t.emplace_back(i, i, 0.05 + w(rng));
    for (int e = len(rng); e > 0; --e) {
      const int j = col(rng);
      if (j == i) continue;
      const double v = w(rng);
      t.emplace_back(i, j, -v);
      t.emplace_back(j, i, -v);
      t.emplace_back(i, i, v);
      t.emplace_back(j, j, v);
    }
  }
  SparseMatrix A(n, n);
  A.setFromTriplets(t.begin(), t.end());
  A.makeCompressed();
  return A;
}

TEST(InterleavedLdlt, MatchesEigenSolveOnEveryColumnAndLeavesPaddingZero) {
  const int n = 700;
  const SparseMatrix A = random_spd(n, 11);
  Eigen::SimplicialLDLT<SparseMatrix> ldlt(A);
  ASSERT_EQ(ldlt.info(), Eigen::Success);
  ASSERT_GT(ldlt.matrixL().nestedExpression().nonZeros(), A.nonZeros() / 2);  // real fill-in
  InterleavedLdlt f;
  copy_factor(ldlt, f);
  ASSERT_EQ(f.n(), n);
  // Seven columns in a stride of 8: two groups of four, the last column padding.
  const int k = 7;
  const std::size_t s = 8;
  std::mt19937 rng(5);
  std::normal_distribution<double> g;
  Eigen::MatrixXd B(n, k);
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < k; ++c) B(i, c) = g(rng);
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
    const SparseMatrix A = random_spd(n, unsigned(n));
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
