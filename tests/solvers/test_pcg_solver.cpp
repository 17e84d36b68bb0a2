#include "solvers/cholmod_solver.h"
#include "solvers/dense_reference.h"
#include "solvers/pcg_solver.h"
#include "test_matrices.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cstring>

namespace mcf {
namespace {

using test::graph_laplacian;
using test::laplacian3d;
using test::random_rhs;
using test::relative_difference;
using test::symmetric_permutation;

const PcgPreconditioner kBuiltIn[] = {PcgPreconditioner::none, PcgPreconditioner::jacobi,
                                      PcgPreconditioner::incomplete_cholesky};

PcgOptions tight(PcgPreconditioner p) {
  PcgOptions o;
  o.preconditioner = p;
  o.relative_tolerance = 1e-13;  // so that cond(A) * tol stays well under the 1e-8 agreement
  o.max_iterations = 5000;
  return o;
}

void expect_all_agree(const SparseMatrix& A) {
  const Eigen::MatrixXd B = random_rhs(A.rows());
  Eigen::MatrixXd Xd, Xc;
  ASSERT_EQ(dense_llt_solve(A, B, Xd).status, SolveStatus::converged);
  CholmodSolver chol;
  ASSERT_EQ(chol.set_matrix(A).status, SolveStatus::converged);
  ASSERT_EQ(chol.solve(B, Xc).status, SolveStatus::converged);
  EXPECT_LT(relative_difference(Xc, Xd), 1e-8);
  for (PcgPreconditioner p : kBuiltIn) {
    SCOPED_TRACE(to_string(p));
    PcgSolver pcg(tight(p));
    ASSERT_EQ(pcg.set_matrix(A).status, SolveStatus::converged);
    Eigen::MatrixXd X;  // empty: cold start from zero
    const SolveReport r = pcg.solve(B, X);
    ASSERT_EQ(r.status, SolveStatus::converged) << r.message;
    EXPECT_GT(r.iterations, 1);
    EXPECT_LT(relative_difference(X, Xd), 1e-8);
    EXPECT_LT(relative_difference(X, Xc), 1e-8);
    EXPECT_LE(r.relative_residual, 1e-13);
  }
}

TEST(PcgSolver, AgreesWithCholmodAndDenseOnLaplacian3d) {
  expect_all_agree(laplacian3d(10, 9, 8));
}
TEST(PcgSolver, AgreesWithCholmodAndDenseOnGraphLaplacian) {
  expect_all_agree(graph_laplacian(700));
}

TEST(PcgSolver, PreconditionersReduceIterations) {
  // Badly scaled diagonal: Jacobi and IC must beat plain CG clearly.
  SparseMatrix A = laplacian3d(10, 10, 10);
  for (int j = 0; j < A.cols(); ++j) A.coeffRef(j, j) += (j % 7) * 50.0;
  const Eigen::MatrixXd B = random_rhs(A.rows());
  int its[3];
  for (int i = 0; i < 3; ++i) {
    PcgSolver pcg(tight(kBuiltIn[i]));
    ASSERT_EQ(pcg.set_matrix(A).status, SolveStatus::converged);
    Eigen::MatrixXd X;
    const SolveReport r = pcg.solve(B, X);
    ASSERT_EQ(r.status, SolveStatus::converged);
    its[i] = r.iterations;
  }
  EXPECT_LT(its[1], its[0]);
  EXPECT_LT(its[2], its[1]);
}

TEST(PcgSolver, NegativeDefiniteIsReported) {
  const SparseMatrix N = -laplacian3d(6, 6, 6);
  const Eigen::MatrixXd B = random_rhs(N.rows());
  for (PcgPreconditioner p : kBuiltIn) {
    SCOPED_TRACE(to_string(p));
    PcgSolver pcg(tight(p));
    const SolveReport s = pcg.set_matrix(N);
    // Jacobi and IC see the negative diagonal at once; plain CG meets p^T A p < 0.
    if (p != PcgPreconditioner::none) {
      EXPECT_EQ(s.status, SolveStatus::not_positive_definite);
    }
    Eigen::MatrixXd X;
    EXPECT_EQ(pcg.solve(B, X).status, SolveStatus::not_positive_definite);
  }
}

TEST(PcgSolver, IndefiniteWithPositiveDiagonalIsReported) {
  // Positive diagonal, one strongly negative eigen-direction that the RHS excites: a 2x2 block
  // [[1, 2], [2, 1]] (eigenvalues 3, -1) embedded in an SPD Laplacian.
  SparseMatrix A = laplacian3d(5, 5, 5);
  A.coeffRef(0, 0) = 1.0;
  A.coeffRef(1, 1) = 1.0;
  A.coeffRef(0, 1) = 2.0;
  A.coeffRef(1, 0) = 2.0;
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(A.rows(), 1);
  B(0, 0) = 1.0;
  B(1, 0) = -1.0;
  PcgOptions o = tight(PcgPreconditioner::jacobi);
  PcgSolver pcg(o);
  ASSERT_EQ(pcg.set_matrix(A).status, SolveStatus::converged);
  Eigen::MatrixXd X;
  EXPECT_EQ(pcg.solve(B, X).status, SolveStatus::not_positive_definite);
  CholmodSolver chol;
  EXPECT_EQ(chol.set_matrix(A).status, SolveStatus::not_positive_definite);
}

TEST(PcgSolver, WarmStartFromExactSolution) {
  const SparseMatrix A = laplacian3d(10, 10, 10);
  const Eigen::MatrixXd B = random_rhs(A.rows());
  CholmodSolver chol;
  Eigen::MatrixXd Xc;
  ASSERT_EQ(chol.set_matrix(A).status, SolveStatus::converged);
  ASSERT_EQ(chol.solve(B, Xc).status, SolveStatus::converged);
  for (PcgPreconditioner p : kBuiltIn) {
    SCOPED_TRACE(to_string(p));
    PcgOptions o;
    o.preconditioner = p;  // default tolerance 1e-10
    PcgSolver pcg(o);
    ASSERT_EQ(pcg.set_matrix(A).status, SolveStatus::converged);
    Eigen::MatrixXd X = Xc;
    const SolveReport r = pcg.solve(B, X);
    EXPECT_EQ(r.status, SolveStatus::converged);
    EXPECT_LE(r.iterations, 1);
    EXPECT_EQ(r.residuals.size(), static_cast<std::size_t>(r.iterations));
    EXPECT_LT(relative_difference(X, Xc), 1e-9);
    // A cold start needs many more: the warm start is really used.
    Eigen::MatrixXd X0;
    EXPECT_GT(pcg.solve(B, X0).iterations, 5);
  }
}

TEST(PcgSolver, IterationCapIsRespected) {
  const SparseMatrix A = laplacian3d(12, 12, 12, 0.01);
  const Eigen::MatrixXd B = random_rhs(A.rows());
  for (PcgPreconditioner p : kBuiltIn) {
    SCOPED_TRACE(to_string(p));
    PcgOptions o = tight(p);
    o.max_iterations = 5;
    PcgSolver pcg(o);
    ASSERT_EQ(pcg.set_matrix(A).status, SolveStatus::converged);
    Eigen::MatrixXd X;
    const SolveReport r = pcg.solve(B, X);
    EXPECT_EQ(r.status, SolveStatus::max_iterations);
    EXPECT_TRUE(r.ok());
    EXPECT_EQ(r.iterations, 5);
    EXPECT_EQ(r.residuals.size(), 5u);
    EXPECT_GT(r.relative_residual, o.relative_tolerance);
  }
}

// give_up_off_course: a cap of 20 iterations that CG cannot meet at its pace (a 1e-12 tolerance
// without a preconditioner) is given up after the first three, said as such; with a tolerance it
// meets, the option changes nothing.
TEST(PcgSolver, GivesUpOnceOffCourseForTheCap) {
  const SparseMatrix A = laplacian3d(12, 12, 12, 0.01);
  const Eigen::MatrixXd B = random_rhs(A.rows());
  PcgOptions o = tight(PcgPreconditioner::none);
  o.max_iterations = 20;
  o.give_up_off_course = true;
  PcgSolver pcg(o);
  ASSERT_EQ(pcg.set_matrix(A).status, SolveStatus::converged);
  Eigen::MatrixXd X;
  const SolveReport r = pcg.solve(B, X);
  EXPECT_EQ(r.status, SolveStatus::max_iterations);
  EXPECT_EQ(r.iterations, 3);
  EXPECT_NE(r.message.find("on course to miss"), std::string::npos) << r.message;
  o.give_up_off_course = false;
  pcg.set_options(o);
  X.resize(0, 0);
  EXPECT_EQ(pcg.solve(B, X).iterations, 20);
  // Reachable: the same iterate as without the option.
  o.relative_tolerance = 1e-2;
  o.max_iterations = 1000;
  pcg.set_options(o);
  Eigen::MatrixXd Y;
  const SolveReport plain = pcg.solve(B, Y);
  o.give_up_off_course = true;
  pcg.set_options(o);
  Eigen::MatrixXd Z;
  const SolveReport guarded = pcg.solve(B, Z);
  EXPECT_EQ(guarded.status, SolveStatus::converged);
  EXPECT_EQ(guarded.iterations, plain.iterations);
  EXPECT_EQ(Y, Z);
}

TEST(PcgSolver, ResidualHistoryDecreasesAndEndsAtTrueResidual) {
  const SparseMatrix A = graph_laplacian(2000, 5, 0.02, 9);
  const Eigen::MatrixXd B = random_rhs(A.rows());
  for (PcgPreconditioner p : kBuiltIn) {
    SCOPED_TRACE(to_string(p));
    PcgOptions o;
    o.preconditioner = p;
    PcgSolver pcg(o);
    ASSERT_EQ(pcg.set_matrix(A).status, SolveStatus::converged);
    Eigen::MatrixXd X;
    const SolveReport r = pcg.solve(B, X);
    ASSERT_EQ(r.status, SolveStatus::converged);
    ASSERT_EQ(r.residuals.size(), static_cast<std::size_t>(r.iterations));
    ASSERT_GE(r.residuals.size(), 3u);
    // CG does not minimise the residual norm, so allow bounded bumps, but the trend is down.
    double best = r.residuals[0];
    for (double v : r.residuals) {
      EXPECT_LE(v, 10.0 * best);
      best = std::min(best, v);
    }
    EXPECT_LT(r.residuals.back(), 1e-3 * r.residuals.front());
    const double recomputed = test::relative_residual(A, B, X);
    EXPECT_EQ(r.residuals.back(), r.relative_residual);
    EXPECT_NEAR(r.residuals.back(), recomputed, 1e-3 * recomputed + 1e-16);
    EXPECT_LE(recomputed, o.relative_tolerance * 1.0001);
  }
}

TEST(PcgSolver, ZeroRightHandSideColumn) {
  const SparseMatrix A = laplacian3d(6, 6, 6);
  Eigen::MatrixXd B = random_rhs(A.rows());
  B.col(1).setZero();
  PcgSolver pcg;
  ASSERT_EQ(pcg.set_matrix(A).status, SolveStatus::converged);
  Eigen::MatrixXd X = Eigen::MatrixXd::Ones(A.rows(), 3);  // warm start that is wrong for column 1
  const SolveReport r = pcg.solve(B, X);
  ASSERT_EQ(r.status, SolveStatus::converged) << r.message;
  EXPECT_EQ(X.col(1).norm(), 0.0);
  Eigen::MatrixXd Xd;
  ASSERT_EQ(dense_llt_solve(A, B, Xd).status, SolveStatus::converged);
  EXPECT_LT(relative_difference(X, Xd), 1e-8);
}

TEST(PcgSolver, ExternalPreconditionerHook) {
  const SparseMatrix A = laplacian3d(9, 9, 9);
  const Eigen::MatrixXd B = random_rhs(A.rows());
  const Eigen::VectorXd d = A.diagonal();
  int calls = 0;
  PcgOptions o = tight(PcgPreconditioner::external);
  PcgSolver ext(o);
  Eigen::MatrixXd X;
  ASSERT_EQ(ext.set_matrix(A).status, SolveStatus::converged);
  EXPECT_EQ(ext.solve(B, X).status, SolveStatus::failed);  // selected but not set
  ext.set_preconditioner([&](const Eigen::MatrixXd& r, Eigen::MatrixXd& z) {
    ++calls;
    z = d.cwiseInverse().asDiagonal() * r;
  });
  const SolveReport re = ext.solve(B, X);
  ASSERT_EQ(re.status, SolveStatus::converged);
  EXPECT_GT(calls, re.iterations - 1);

  PcgSolver jac(tight(PcgPreconditioner::jacobi));
  ASSERT_EQ(jac.set_matrix(A).status, SolveStatus::converged);
  Eigen::MatrixXd Xj;
  const SolveReport rj = jac.solve(B, Xj);
  EXPECT_EQ(re.iterations, rj.iterations);
  EXPECT_LT(relative_difference(X, Xj), 1e-10);
}

TEST(PcgSolver, SameAnswerAfterValueUpdateAndOptionChange) {
  const SparseMatrix A1 = laplacian3d(7, 7, 7, 0.1, 1);
  const SparseMatrix A2 = laplacian3d(7, 7, 7, 0.5, 2, 3.0);
  const Eigen::MatrixXd B = random_rhs(A1.rows());
  PcgSolver pcg(tight(PcgPreconditioner::incomplete_cholesky));
  Eigen::MatrixXd X, Xd;
  ASSERT_EQ(pcg.set_matrix(A1).status, SolveStatus::converged);
  ASSERT_EQ(pcg.solve(B, X).status, SolveStatus::converged);
  ASSERT_EQ(pcg.set_matrix(A2).status, SolveStatus::converged);  // same pattern: values only
  ASSERT_EQ(pcg.solve(B, X).status, SolveStatus::converged);
  ASSERT_EQ(dense_llt_solve(A2, B, Xd).status, SolveStatus::converged);
  EXPECT_LT(relative_difference(X, Xd), 1e-8);
  pcg.set_options(tight(PcgPreconditioner::jacobi));
  X.setZero();
  ASSERT_EQ(pcg.solve(B, X).status, SolveStatus::converged);
  EXPECT_LT(relative_difference(X, Xd), 1e-8);
  EXPECT_EQ(pcg.name(), "pcg-jacobi");
}

// With a third term s S too: bitwise the iterate of set_matrix on sum_on_pattern's matrix.
TEST(PcgSolver, SetMatrixSumWithAThirdTermEqualsSetMatrixOfTheSum) {
  const SparseMatrix M = laplacian3d(7, 7, 7, 0.1, 1), K = laplacian3d(7, 7, 7, 0.5, 2, 3.0);
  const SparseMatrix S = laplacian3d(7, 7, 7, 0.0, 3, 2.0);
  ASSERT_TRUE(same_pattern(M, S));
  PcgOptions o = tight(PcgPreconditioner::incomplete_cholesky);
  o.max_iterations = 7;
  PcgSolver fused(o), reference(o);
  SparseMatrix sum = M;
  sum_on_pattern(MatrixSum(1.0, M, 0.01, K, 0.3, S), sum);
  ASSERT_TRUE(fused.set_matrix_sum(MatrixSum(1.0, M, 0.01, K, 0.3, S)).ok());
  ASSERT_TRUE(reference.set_matrix(sum).ok());
  const Eigen::MatrixXd B = random_rhs(sum.rows());
  Eigen::MatrixXd X1, X2;
  ASSERT_TRUE(fused.solve(B, X1).ok() && reference.solve(B, X2).ok());
  EXPECT_EQ((X1 - X2).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_GT(X1.norm(), 0.0);
}

// set_matrix_sum writes a M + b K straight into the solver's copy: bitwise the iterate of
// set_matrix on sum_on_pattern's matrix, through a value refresh and a change of pattern (which
// must rebuild the incomplete Cholesky's ordering); operands off one pattern get the general sum.
TEST(PcgSolver, SetMatrixSumEqualsSetMatrixOfTheSum) {
  const SparseMatrix M1 = laplacian3d(7, 7, 7, 0.1, 1), K1 = laplacian3d(7, 7, 7, 0.5, 2, 3.0);
  const SparseMatrix M2 = graph_laplacian(700, 4, 0.05), K2 = graph_laplacian(700, 4, 0.3);
  ASSERT_TRUE(same_pattern(M1, K1));
  ASSERT_TRUE(same_pattern(M2, K2));
  struct Call {
    const SparseMatrix *M, *K;
    double a, b;
  };
  PcgOptions o = tight(PcgPreconditioner::incomplete_cholesky);
  o.max_iterations = 7;  // stop early: an iterate depends on every rounding of A and of the factor
  PcgSolver fused(o), reference(o);
  for (const Call c :
       {Call{&M1, &K1, 1.0, 0.01}, Call{&M1, &K1, 0.5, 0.2}, Call{&M2, &K2, 1.0, 1e-3}}) {
    SparseMatrix S = *c.M;
    sum_on_pattern(c.a, *c.M, c.b, *c.K, S);
    ASSERT_TRUE(fused.set_matrix_sum(c.a, *c.M, c.b, *c.K).ok());
    ASSERT_TRUE(reference.set_matrix(S).ok());
    const Eigen::MatrixXd B = random_rhs(S.rows());
    Eigen::MatrixXd X1, X2;
    const SolveReport r1 = fused.solve(B, X1), r2 = reference.solve(B, X2);
    ASSERT_TRUE(r1.ok() && r2.ok());
    EXPECT_EQ(r1.iterations, r2.iterations);
    EXPECT_EQ((X1 - X2).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_GT(X1.norm(), 0.0);
  }
  const SparseMatrix D = SparseMatrix(M2.diagonal().asDiagonal());
  ASSERT_FALSE(summable(M2, D));
  // Solved to convergence on the solver that held M2 + 1e-3 K2 before: the dense solution of the
  // general sum, not of the old matrix.
  fused.set_options(tight(PcgPreconditioner::incomplete_cholesky));
  ASSERT_TRUE(fused.set_matrix_sum(1.0, M2, 0.5, D).ok());
  const SparseMatrix G = M2 + 0.5 * D;
  const Eigen::MatrixXd B = random_rhs(M2.rows());
  Eigen::MatrixXd X, Xd;
  ASSERT_EQ(fused.solve(B, X).status, SolveStatus::converged);
  ASSERT_EQ(dense_llt_solve(G, B, Xd).status, SolveStatus::converged);
  EXPECT_LT(relative_difference(X, Xd), 1e-8);
}

// A pattern key (linear_solver.h) vouches for the pattern: no comparison, only the values are
// copied and the incomplete Cholesky keeps its ordering. Any other key, or none, is compared: a
// symmetric permutation with the same size and nonzero count is a new pattern. A key never
// saves a matrix of another size from being copied whole. Every answer is the dense solve's.
TEST(PcgSolver, PatternKeyVouchesWithoutComparing) {
  const SparseMatrix A1 = laplacian3d(7, 6, 5, 0.1, 51);
  const SparseMatrix A2 = laplacian3d(7, 6, 5, 0.6, 52, 2.0);  // same pattern, new values
  const SparseMatrix A3 = symmetric_permutation(A2, 11);       // 210 and 11 coprime
  ASSERT_EQ(A3.nonZeros(), A1.nonZeros());
  ASSERT_FALSE(same_pattern(A1, A3));
  const SparseMatrix small = laplacian3d(4, 4, 4);
  const std::uint64_t key = new_pattern_key(), other = new_pattern_key();
  const auto keyed = [](std::uint64_t k) {
    HierarchyView v;
    v.pattern_key = k;
    return v;
  };
  PcgSolver pcg(tight(PcgPreconditioner::incomplete_cholesky));
  const auto expect_solves = [&](const SparseMatrix& A) {
    const Eigen::MatrixXd B = random_rhs(A.rows());
    Eigen::MatrixXd X, Xd;
    ASSERT_EQ(pcg.solve(B, X).status, SolveStatus::converged);
    ASSERT_EQ(dense_llt_solve(A, B, Xd).status, SolveStatus::converged);
    EXPECT_LT(relative_difference(X, Xd), 1e-8);
  };
  ASSERT_TRUE(pcg.set_matrix(A1, keyed(key)).ok());
  ASSERT_TRUE(pcg.set_matrix(A2, keyed(key)).ok());
  EXPECT_EQ(pcg.pattern_comparisons(), 0);
  expect_solves(A2);
  ASSERT_TRUE(pcg.set_matrix_sum(1.0, A1, 0.0, A2, keyed(key)).ok());  // the sum honours it too
  EXPECT_EQ(pcg.pattern_comparisons(), 0);
  expect_solves(A1);

  ASSERT_TRUE(pcg.set_matrix(A2, keyed(other)).ok());  // another key: compared, same pattern
  EXPECT_EQ(pcg.pattern_comparisons(), 1);
  expect_solves(A2);
  ASSERT_TRUE(pcg.set_matrix(A3).ok());  // none: compared, a new pattern
  EXPECT_EQ(pcg.pattern_comparisons(), 2);
  expect_solves(A3);

  ASSERT_TRUE(pcg.set_matrix(A1, keyed(key)).ok());  // the first key again: compared, as it
  EXPECT_EQ(pcg.pattern_comparisons(), 3);           // vouches for A3's pattern no more
  expect_solves(A1);
  ASSERT_TRUE(pcg.set_matrix(small, keyed(key)).ok());  // the same key, another size
  EXPECT_EQ(pcg.pattern_comparisons(), 3);
  expect_solves(small);
}

TEST(PcgSolver, MultiplyMatchesEigen) {
  const SparseMatrix A = graph_laplacian(9000, 4, 0.05, 4);  // > 2 chunks of 4096 rows
  const Eigen::MatrixXd X = random_rhs(A.rows());
  PcgSolver pcg;
  ASSERT_EQ(pcg.set_matrix(A).status, SolveStatus::converged);
  Eigen::MatrixXd Y;
  pcg.multiply(X, Y);
  EXPECT_LT(relative_difference(Y, A * X), 1e-14);
}

TEST(PcgSolver, BitwiseIdenticalForOneAndTwoThreads) {
  const SparseMatrix A = laplacian3d(22, 22, 22, 0.05);  // 10648 rows: three reduction chunks
  const Eigen::MatrixXd B = random_rhs(A.rows());
  for (PcgPreconditioner p : kBuiltIn) {
    SCOPED_TRACE(to_string(p));
    auto run = [&](int threads, Eigen::MatrixXd& X) {
      tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
      PcgOptions o;
      o.preconditioner = p;
      PcgSolver pcg(o);
      EXPECT_EQ(pcg.set_matrix(A).status, SolveStatus::converged);
      X.resize(0, 0);
      return pcg.solve(B, X);
    };
    Eigen::MatrixXd X1, X2;
    const SolveReport r1 = run(1, X1);
    const SolveReport r2 = run(2, X2);
    ASSERT_EQ(r1.status, SolveStatus::converged);
    ASSERT_EQ(r1.iterations, r2.iterations);
    ASSERT_EQ(X1.size(), X2.size());
    EXPECT_EQ(std::memcmp(X1.data(), X2.data(), sizeof(double) * X1.size()), 0);
    EXPECT_EQ(r1.residuals, r2.residuals);
    EXPECT_EQ(r1.relative_residual, r2.relative_residual);
  }
}

}  // namespace
}  // namespace mcf
