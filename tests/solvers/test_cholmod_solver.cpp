#include "solvers/blas_threads.h"
#include "solvers/cholmod_solver.h"
#include "solvers/dense_reference.h"
#include "test_matrices.h"

#include <gtest/gtest.h>

#include <limits>
#include <utility>

namespace mcf {
namespace {

using test::graph_laplacian;
using test::laplacian3d;
using test::random_rhs;
using test::relative_difference;
using test::symmetric_permutation;

TEST(CholmodSolver, MatchesDenseOnLaplacian3d) {
  const SparseMatrix A = laplacian3d(10, 9, 8);
  const Eigen::MatrixXd B = random_rhs(A.rows());
  Eigen::MatrixXd Xd, Xc;
  ASSERT_EQ(dense_llt_solve(A, B, Xd).status, SolveStatus::converged);
  CholmodSolver s;
  ASSERT_EQ(s.set_matrix(A).status, SolveStatus::converged);
  const SolveReport r = s.solve(B, Xc);
  ASSERT_EQ(r.status, SolveStatus::converged) << r.message;
  EXPECT_EQ(r.iterations, 1);
  EXPECT_TRUE(s.is_supernodal());
  EXPECT_GT(s.factor_nonzeros(), A.nonZeros() / 2);
  EXPECT_LT(relative_difference(Xc, Xd), 1e-8);
  ASSERT_EQ(r.residuals.size(), 1u);
  EXPECT_EQ(r.residuals[0], r.relative_residual);
  EXPECT_LT(r.relative_residual, 1e-12);
  // The reported residual is the true one.
  EXPECT_NEAR(r.relative_residual, test::relative_residual(A, B, Xc), 1e-14);
}

// The solver chooses OpenBLAS's threads for its own calls, under the caller's cap, and restores
// the cap after: kept, a count (capped), or auto (one for a small system, the cap for a large one).
TEST(CholmodSolver, ChoosesItsBlasThreadsUnderTheCallersCap) {
  const ScopedBlasThreads two(2);
  if (blas_threads() < 2) GTEST_SKIP() << "OpenBLAS runs one thread on this machine";
  const SparseMatrix small = laplacian3d(6, 6, 6);      // 216 unknowns
  const SparseMatrix large = laplacian3d(150, 150, 1);  // 22500 unknowns, a 2D grid: fast
  ASSERT_GE(large.rows(), kBlasThreadsFromDimension);
  const auto used = [](int request, const SparseMatrix& A) {
    CholmodSolver s(request);
    EXPECT_EQ(s.settings().size(), 0u);  // nothing to say before a factorization
    EXPECT_EQ(s.set_matrix(A).status, SolveStatus::converged);
    EXPECT_EQ(blas_threads(), 2);  // the cap is back
    EXPECT_EQ(s.settings().at(0).first, "blas_threads");
    EXPECT_EQ(s.settings().at(0).second, std::to_string(s.blas_threads_used()));
    return s.blas_threads_used();
  };
  EXPECT_EQ(used(kKeepBlasThreads, small), 2);
  EXPECT_EQ(used(1, small), 1);
  EXPECT_EQ(used(8, small), 2);
  EXPECT_EQ(used(kAutoBlasThreads, small), 1);
  EXPECT_EQ(used(kAutoBlasThreads, large), 2);
}

TEST(CholmodSolver, MatchesDenseOnGraphLaplacian) {
  const SparseMatrix A = graph_laplacian(700);
  const Eigen::MatrixXd B = random_rhs(A.rows());
  Eigen::MatrixXd Xd, Xc;
  ASSERT_EQ(dense_llt_solve(A, B, Xd).status, SolveStatus::converged);
  CholmodSolver s;
  ASSERT_EQ(s.set_matrix(A).status, SolveStatus::converged);
  ASSERT_EQ(s.solve(B, Xc).status, SolveStatus::converged);
  EXPECT_LT(relative_difference(Xc, Xd), 1e-8);
}

TEST(CholmodSolver, RefactorizationReusesAnalysis) {
  const SparseMatrix A1 = laplacian3d(8, 8, 8, 0.1, 11);
  const SparseMatrix A2 = laplacian3d(8, 8, 8, 0.7, 12, 2.5);  // same pattern, new values
  ASSERT_TRUE(A1.nonZeros() == A2.nonZeros());
  const Eigen::MatrixXd B = random_rhs(A1.rows());
  CholmodSolver s;
  Eigen::MatrixXd X, Xd;
  ASSERT_EQ(s.set_matrix(A1).status, SolveStatus::converged);
  ASSERT_EQ(s.solve(B, X).status, SolveStatus::converged);
  ASSERT_EQ(s.set_matrix(A2).status, SolveStatus::converged);
  ASSERT_EQ(s.solve(B, X).status, SolveStatus::converged);
  EXPECT_EQ(s.analyses(), 1);
  EXPECT_EQ(s.factorizations(), 2);
  ASSERT_EQ(dense_llt_solve(A2, B, Xd).status, SolveStatus::converged);
  EXPECT_LT(relative_difference(X, Xd), 1e-8);

  // A different pattern (and size) must be analysed again.
  const SparseMatrix A3 = graph_laplacian(400);
  const Eigen::MatrixXd B3 = random_rhs(A3.rows());
  ASSERT_EQ(s.set_matrix(A3).status, SolveStatus::converged);
  EXPECT_EQ(s.analyses(), 2);
  ASSERT_EQ(s.solve(B3, X).status, SolveStatus::converged);
  ASSERT_EQ(dense_llt_solve(A3, B3, Xd).status, SolveStatus::converged);
  EXPECT_LT(relative_difference(X, Xd), 1e-8);
}

TEST(CholmodSolver, SameSizeDifferentPatternReanalyses) {
  const SparseMatrix A1 = graph_laplacian(300, 4, 0.05, 5);
  const SparseMatrix A2 = graph_laplacian(300, 4, 0.05, 6);
  const Eigen::MatrixXd B = random_rhs(300);
  CholmodSolver s;
  Eigen::MatrixXd X, Xd;
  ASSERT_EQ(s.set_matrix(A1).status, SolveStatus::converged);
  ASSERT_EQ(s.set_matrix(A2).status, SolveStatus::converged);
  EXPECT_EQ(s.analyses(), 2);
  ASSERT_EQ(s.solve(B, X).status, SolveStatus::converged);
  ASSERT_EQ(dense_llt_solve(A2, B, Xd).status, SolveStatus::converged);
  EXPECT_LT(relative_difference(X, Xd), 1e-8);
}

// The last set_matrix's factor solves A: against a dense solve of A for a random right-hand side.
void expect_factor_of(CholmodSolver& s, const SparseMatrix& A) {
  const Eigen::MatrixXd B = random_rhs(A.rows());
  Eigen::MatrixXd X, Xd;
  ASSERT_TRUE(s.solve(B, X).ok());
  ASSERT_TRUE(dense_llt_solve(A, B, Xd).ok());
  EXPECT_LT(relative_difference(X, Xd), 1e-8);
}

// A2 after A1, both of one size and number of nonzeros but of two patterns: compared once, seen
// as new (a second analysis), and the factor is A2's.
void expect_reanalysed(const SparseMatrix& A1, const SparseMatrix& A2) {
  ASSERT_EQ(A1.nonZeros(), A2.nonZeros());
  ASSERT_FALSE(same_pattern(A1, A2));
  CholmodSolver s;
  ASSERT_TRUE(s.set_matrix(A1).ok());
  ASSERT_TRUE(s.set_matrix(A2).ok());
  EXPECT_EQ(s.pattern_comparisons(), 1);
  EXPECT_EQ(s.analyses(), 2);
  expect_factor_of(s, A2);
}

// Same size and number of nonzeros, another pattern: a symmetric permutation of a Laplacian.
// The comparison must see it, and the factor must be the new matrix's.
TEST(CholmodSolver, PermutedPatternWithTheSameNonzerosReanalyses) {
  const SparseMatrix A1 = laplacian3d(6, 5, 4, 0.1, 21);
  expect_reanalysed(A1, symmetric_permutation(A1, 7));  // 120 and 7 coprime
}

// Only the lower triangle is factorized, and it is gathered from A by position: a matrix with
// the same lower triangle and the same number of nonzeros, whose upper triangle keeps a stored
// zero in another column, shifts the positions of every column in between. Taking the cached
// pattern for it would gather the wrong values.
TEST(CholmodSolver, ShiftedPositionsAreANewPattern) {
  const SparseMatrix L = laplacian3d(5, 5, 4, 0.2, 31);
  const int n = int(L.rows());
  const auto with_stored_zero = [&](int column) {
    SparseMatrix A = L;
    A.coeffRef(0, column) = 0.0;  // a stored zero above the diagonal: A stays symmetric in value
    A.makeCompressed();
    return A;
  };
  ASSERT_EQ(L.coeff(0, n / 2), 0.0);
  ASSERT_EQ(L.coeff(0, n - 1), 0.0);
  const SparseMatrix A1 = with_stored_zero(n / 2);
  SparseMatrix A2 = with_stored_zero(n - 1);
  // A2 with other values than A1, so a wrong gather would show in the solution.
  for (Eigen::Index j = 0; j < n; ++j) A2.coeffRef(j, j) *= 1.5;
  expect_reanalysed(A1, A2);
}

// A pattern key (linear_solver.h) vouches for the pattern: no comparison, no new analysis. Any
// other key, or none, is compared; a key never saves a matrix of another size from analysis.
TEST(CholmodSolver, PatternKeyVouchesWithoutComparing) {
  const SparseMatrix A1 = laplacian3d(8, 7, 6, 0.1, 41);
  const SparseMatrix A2 = laplacian3d(8, 7, 6, 0.6, 42, 2.0);  // same pattern, new values
  const std::uint64_t key = new_pattern_key(), other = new_pattern_key();
  const auto keyed = [](std::uint64_t k) {
    HierarchyView v;
    v.pattern_key = k;
    return v;
  };
  CholmodSolver s;
  ASSERT_TRUE(s.set_matrix(A1, keyed(key)).ok());
  ASSERT_TRUE(s.set_matrix(A2, keyed(key)).ok());
  EXPECT_EQ(s.pattern_comparisons(), 0);
  EXPECT_EQ(s.analyses(), 1);
  EXPECT_EQ(s.factorizations(), 2);
  expect_factor_of(s, A2);

  ASSERT_TRUE(s.set_matrix(A1, keyed(other)).ok());  // another key: compared, still reused
  ASSERT_TRUE(s.set_matrix(A2).ok());                // none: compared
  EXPECT_EQ(s.pattern_comparisons(), 2);
  EXPECT_EQ(s.analyses(), 1);

  const SparseMatrix small = laplacian3d(4, 4, 4);
  ASSERT_TRUE(s.set_matrix(small, keyed(key)).ok());  // the old key, another size
  EXPECT_EQ(s.analyses(), 2);
  expect_factor_of(s, small);
}

TEST(CholmodSolver, IndefiniteIsReportedAndRecoverable) {
  // Laplacian minus a shift: some eigenvalues negative, diagonal still positive.
  SparseMatrix A = laplacian3d(8, 8, 8);
  SparseMatrix shifted = A;
  for (int j = 0; j < shifted.cols(); ++j) shifted.coeffRef(j, j) -= 3.0;
  const Eigen::MatrixXd B = random_rhs(A.rows());
  CholmodSolver s;
  Eigen::MatrixXd X;
  const SolveReport f = s.set_matrix(shifted);
  EXPECT_EQ(f.status, SolveStatus::not_positive_definite) << f.message;
  EXPECT_FALSE(s.factorized());
  EXPECT_EQ(s.solve(B, X).status, SolveStatus::not_positive_definite);

  // Same pattern, SPD values again: the flow can go on with the same solver object.
  ASSERT_EQ(s.set_matrix(A).status, SolveStatus::converged);
  EXPECT_EQ(s.analyses(), 1);
  ASSERT_EQ(s.solve(B, X).status, SolveStatus::converged);
  Eigen::MatrixXd Xd;
  ASSERT_EQ(dense_llt_solve(A, B, Xd).status, SolveStatus::converged);
  EXPECT_LT(relative_difference(X, Xd), 1e-8);

  // Negative definite too.
  const SparseMatrix N = -A;
  EXPECT_EQ(s.set_matrix(N).status, SolveStatus::not_positive_definite);
}

TEST(CholmodSolver, RejectsNonFiniteAndBadShapes) {
  SparseMatrix A = laplacian3d(4, 4, 4);
  CholmodSolver s;
  Eigen::MatrixXd X;
  EXPECT_EQ(s.solve(random_rhs(64), X).status, SolveStatus::failed);  // no matrix yet
  A.coeffRef(3, 3) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(s.set_matrix(A).status, SolveStatus::numerical_issue);
  const SparseMatrix R(3, 4);
  EXPECT_EQ(s.set_matrix(R).status, SolveStatus::failed);
  ASSERT_EQ(s.set_matrix(laplacian3d(4, 4, 4)).status, SolveStatus::converged);
  EXPECT_EQ(s.solve(random_rhs(63), X).status, SolveStatus::failed);
}

// A right-hand side whose first column holds a NaN and whose second is finite: the solve's
// report is a numerical issue for both direct solvers (the dense reference let the finite column
// overwrite the NaN's residual and reported it converged at 2e-16).
TEST(CholmodSolver, ANonFiniteColumnBeforeAFiniteOneIsANumericalIssue) {
  const SparseMatrix A = laplacian3d(4, 4, 4);
  Eigen::MatrixXd B = random_rhs(A.rows(), 2);
  B(0, 0) = std::numeric_limits<double>::quiet_NaN();
  Eigen::MatrixXd X;
  CholmodSolver cholmod;
  ASSERT_EQ(cholmod.set_matrix(A).status, SolveStatus::converged);
  EXPECT_EQ(cholmod.solve(B, X).status, SolveStatus::numerical_issue);
  EXPECT_EQ(dense_llt_solve(A, B, X).status, SolveStatus::numerical_issue);
  B.col(0).swap(B.col(1));  // finite first, then the NaN: both saw this one
  EXPECT_EQ(cholmod.solve(B, X).status, SolveStatus::numerical_issue);
  EXPECT_EQ(dense_llt_solve(A, B, X).status, SolveStatus::numerical_issue);
}

TEST(CholmodSolver, AcceptsUncompressedInput) {
  SparseMatrix A = laplacian3d(5, 5, 5);
  SparseMatrix U = A;
  U.reserve(Eigen::VectorXi::Constant(U.cols(), 10));  // leaves the matrix uncompressed
  ASSERT_FALSE(U.isCompressed());
  const Eigen::MatrixXd B = random_rhs(A.rows());
  CholmodSolver s;
  Eigen::MatrixXd X, Xd;
  ASSERT_EQ(s.set_matrix(U).status, SolveStatus::converged);
  ASSERT_EQ(s.solve(B, X).status, SolveStatus::converged);
  ASSERT_EQ(dense_llt_solve(A, B, Xd).status, SolveStatus::converged);
  EXPECT_LT(relative_difference(X, Xd), 1e-8);
}

// With a third term s S too: bitwise the factor of sum_on_pattern's a M + b K + s S.
TEST(CholmodSolver, SetMatrixSumWithAThirdTermIsBitwiseTheFactorOfTheSum) {
  const SparseMatrix M = laplacian3d(7, 6, 5, 0.1, 3);
  const SparseMatrix K = laplacian3d(7, 6, 5, 0.7, 4, 2.5);
  const SparseMatrix S = laplacian3d(7, 6, 5, 0.0, 5, 1.5);
  ASSERT_TRUE(same_pattern(M, K) && same_pattern(M, S));
  const Eigen::MatrixXd B = random_rhs(M.rows());
  CholmodSolver fused, plain;
  SparseMatrix sum = M;
  sum_on_pattern(MatrixSum(1.0, M, 0.05, K, 0.2, S), sum);
  ASSERT_TRUE(plain.set_matrix(sum).ok());
  ASSERT_TRUE(fused.set_matrix_sum(MatrixSum(1.0, M, 0.05, K, 0.2, S)).ok());
  Eigen::MatrixXd Xp, Xf;
  ASSERT_TRUE(plain.solve(B, Xp).ok());
  ASSERT_TRUE(fused.solve(B, Xf).ok());
  EXPECT_TRUE(Xf == Xp);
  EXPECT_LT(relative_difference(SparseMatrix(M + 0.05 * K + 0.2 * S) * Xf, B), 1e-10);
}

// set_matrix_sum forms a M + b K in the lower triangle CHOLMOD reads: the factor, and so every
// solution, is bitwise that of set_matrix on the sum formed by sum_on_pattern; the analysis is
// reused; NaN/inf in the sum is refused, on a new pattern too, and the next finite sum works.
TEST(CholmodSolver, SetMatrixSumIsBitwiseTheFactorOfTheSum) {
  const SparseMatrix M = laplacian3d(7, 6, 5, 0.1, 3);
  const SparseMatrix K = laplacian3d(7, 6, 5, 0.7, 4, 2.5);  // same pattern, other values
  ASSERT_TRUE(same_pattern(M, K));
  // K's values on M's index arrays, as a basis hands them out (core/sparse.h SparseView).
  const Eigen::Map<const SparseMatrix> K_view(K.rows(), K.cols(), K.nonZeros(), M.outerIndexPtr(),
                                              M.innerIndexPtr(), K.valuePtr());
  const Eigen::MatrixXd B = random_rhs(M.rows());
  CholmodSolver fused, plain;
  SparseMatrix S = M;
  for (const auto& [a, b] : {std::pair{1.0, 0.05}, std::pair{2.0, 0.3}}) {
    sum_on_pattern(a, M, b, K, S);
    ASSERT_TRUE(plain.set_matrix(S).ok());
    ASSERT_TRUE(fused.set_matrix_sum(a, M, b, K_view).ok());
    Eigen::MatrixXd Xp, Xf;
    ASSERT_TRUE(plain.solve(B, Xp).ok());
    ASSERT_TRUE(fused.solve(B, Xf).ok());
    EXPECT_TRUE(Xf == Xp) << "a = " << a << ", b = " << b;
    Eigen::MatrixXd Xd;
    ASSERT_TRUE(dense_llt_solve(S, B, Xd).ok());
    EXPECT_LT(relative_difference(Xf, Xd), 1e-8);
  }
  EXPECT_EQ(fused.analyses(), 1);
  EXPECT_EQ(fused.factorizations(), 2);

  // A NaN in a lower-triangle entry of K, first on a fresh solver (a new pattern), then again.
  SparseMatrix K_nan = K;
  K_nan.coeffRef(5, 4) = std::numeric_limits<double>::quiet_NaN();
  CholmodSolver fresh;
  EXPECT_EQ(fresh.set_matrix_sum(1.0, M, 0.1, K_nan).status, SolveStatus::numerical_issue);
  EXPECT_FALSE(fresh.factorized());
  Eigen::MatrixXd X;
  EXPECT_EQ(fresh.solve(B, X).status, SolveStatus::numerical_issue);
  ASSERT_TRUE(fresh.set_matrix_sum(1.0, M, 0.1, K).ok());
  ASSERT_TRUE(fresh.solve(B, X).ok());
  EXPECT_EQ(fresh.analyses(), 1);
  EXPECT_EQ(fused.set_matrix_sum(1.0, M, 0.1, K_nan).status, SolveStatus::numerical_issue);

  // Off one pattern: the default (Eigen's general sum), still the right solution.
  const SparseMatrix D = SparseMatrix(Eigen::VectorXd::Constant(M.rows(), 3.0).asDiagonal());
  ASSERT_TRUE(fused.set_matrix_sum(1.0, M, 0.5, D).ok());
  ASSERT_TRUE(fused.solve(B, X).ok());
  Eigen::MatrixXd Xd;
  ASSERT_TRUE(dense_llt_solve(SparseMatrix(M + 0.5 * D), B, Xd).ok());
  EXPECT_LT(relative_difference(X, Xd), 1e-8);
}

TEST(CholmodSolver, VersionString) {
  const std::string v = CholmodSolver::version();
  EXPECT_EQ(v.rfind("CHOLMOD ", 0), 0u) << v;
  EXPECT_NE(v.find('.'), std::string::npos);
}

TEST(DenseReference, ReportsIndefiniteAndTooLarge) {
  SparseMatrix A = laplacian3d(4, 4, 4);
  Eigen::MatrixXd X;
  EXPECT_EQ(dense_llt_solve(SparseMatrix(-A), random_rhs(64), X).status,
            SolveStatus::not_positive_definite);
  EXPECT_EQ(dense_llt_solve(A, random_rhs(64), X, 10).status, SolveStatus::failed);
  const SolveReport r = dense_llt_solve(A, random_rhs(64), X);
  EXPECT_EQ(r.status, SolveStatus::converged);
  EXPECT_LT(r.relative_residual, 1e-13);
}

}  // namespace
}  // namespace mcf
