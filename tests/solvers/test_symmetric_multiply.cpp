// symmetric_multiply against Eigen's own (serial, scattering) sparse product, and its
// independence of the thread count.
#include "solvers/symmetric_multiply.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cstring>
#include <random>
#include <vector>

namespace mcf {
namespace {

/// A random symmetric matrix with varying row lengths (an uneven random pattern plus a diagonal)
/// and n > one 4096-row chunk so that several chunks and both threads are used.
SparseMatrix random_symmetric(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> col(0, n - 1), len(0, 12);
  std::uniform_real_distribution<double> val(-1.0, 1.0);
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < n; ++i) {
    t.emplace_back(i, i, 4.0 + val(rng));
    for (int e = len(rng); e > 0; --e) {
      const int j = col(rng);
      const double v = val(rng);
      t.emplace_back(i, j, v);
      t.emplace_back(j, i, v);
    }
  }
  SparseMatrix A(n, n);
  A.setFromTriplets(t.begin(), t.end());
  A.makeCompressed();
  return A;
}

TEST(SymmetricMultiply, MatchesEigenProductForAnyColumnCount) {
  const SparseMatrix A = random_symmetric(10007, 3);
  std::mt19937 rng(7);
  std::normal_distribution<double> g;
  for (int k : {1, 2, 3, 4, 5}) {
    Eigen::MatrixXd X(A.rows(), k);
    for (Eigen::Index i = 0; i < X.size(); ++i) X.data()[i] = g(rng);
    Eigen::MatrixXd Y;
    symmetric_multiply(A, X, Y);
    const Eigen::MatrixXd ref = A * X;
    ASSERT_EQ(Y.rows(), A.rows());
    ASSERT_EQ(Y.cols(), k);
    EXPECT_LE((Y - ref).cwiseAbs().maxCoeff(), 1e-13 * ref.cwiseAbs().maxCoeff()) << "k = " << k;
  }
}

TEST(SymmetricMultiply, CoefficientsInMatrixOut) {
  const SparseMatrix A = random_symmetric(500, 5);
  const Eigen::Matrix<double, Eigen::Dynamic, 3> X =
      Eigen::Matrix<double, Eigen::Dynamic, 3>::Random(500, 3);
  const Eigen::Matrix<double, Eigen::Dynamic, 3> Y = symmetric_multiply(A, X);
  EXPECT_LE((Y - A * X).cwiseAbs().maxCoeff(), 1e-13);
}

TEST(SymmetricMultiply, SameBitsForOneAndTwoThreads) {
  const SparseMatrix A = random_symmetric(20011, 11);
  const Eigen::MatrixXd X = Eigen::MatrixXd::Random(A.rows(), 3);
  Eigen::MatrixXd Y1, Y2;
  {
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    symmetric_multiply(A, X, Y1);
  }
  {
    tbb::global_control two(tbb::global_control::max_allowed_parallelism, 2);
    symmetric_multiply(A, X, Y2);
  }
  EXPECT_EQ(0, std::memcmp(Y1.data(), Y2.data(), sizeof(double) * std::size_t(Y1.size())));
}

TEST(SymmetricMultiply, RejectsMismatchedSizes) {
  const SparseMatrix A = random_symmetric(100, 1);
  Eigen::MatrixXd Y;
  const Eigen::MatrixXd short_x = Eigen::MatrixXd::Zero(99, 3), x50 = Eigen::MatrixXd::Zero(50, 1);
  EXPECT_THROW(symmetric_multiply(A, short_x, Y), std::invalid_argument);
  SparseMatrix R(100, 50);
  R.makeCompressed();
  EXPECT_THROW(symmetric_multiply(R, x50, Y), std::invalid_argument);
}

}  // namespace
}  // namespace mcf
