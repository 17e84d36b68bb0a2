// PETSc's KSP behind LinearSolver (solvers/petsc_solver.h) against CHOLMOD, an independent
// direct solver: the default CG + GAMG and BoomerAMG reach the tolerance on the true residual,
// a KSP that stops short says so, bad options are refused naming the option, and a pattern is
// handed to PETSc once. Skipped in a build without PETSc, where the solver must refuse.

#include "solvers/cholmod_solver.h"
#include "solvers/petsc_runtime.h"
#include "solvers/petsc_solver.h"
#include "test_matrices.h"

#include <gtest/gtest.h>

#include <map>
#include <stdexcept>
#include <string>

namespace mcf {
namespace {

using test::laplacian3d;
using test::random_rhs;
using test::relative_difference;
using test::relative_residual;

#define SKIP_WITHOUT_PETSC() \
  if (!petsc_available()) GTEST_SKIP() << "built without PETSc"

Eigen::MatrixXd cholmod_solution(const SparseMatrix& A, const Eigen::MatrixXd& B) {
  CholmodSolver chol;
  EXPECT_EQ(chol.set_matrix(A).status, SolveStatus::converged);
  Eigen::MatrixXd X;
  EXPECT_EQ(chol.solve(B, X).status, SolveStatus::converged);
  return X;
}

std::string refusal(const std::string& options) {
  try {
    PetscSolverOptions o;
    o.options = options;
    PetscSolver solver(o);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(PetscSolver, RefusedWithoutPetsc) {
  if (petsc_available()) GTEST_SKIP() << "built with PETSc";
  try {
    PetscSolver solver;
    FAIL() << "constructed without PETSc";
  } catch (const PetscUnavailable& e) {
    EXPECT_NE(std::string(e.what()).find("libpetsc-real-dev"), std::string::npos) << e.what();
  }
}

TEST(PetscSolver, DefaultCgGamgMatchesCholmod) {
  SKIP_WITHOUT_PETSC();
  // The paper's baseline: CG with smoothed-aggregation AMG to relative residual 1e-10.
  const SparseMatrix A = laplacian3d(14, 13, 12, 0.01);
  const Eigen::MatrixXd B = random_rhs(A.rows());
  PetscSolver solver;
  EXPECT_EQ(solver.name(), "petsc-cg-gamg");
  ASSERT_EQ(solver.set_matrix(A).status, SolveStatus::converged);
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(A.rows(), 3);
  const SolveReport r = solver.solve(B, X);
  ASSERT_EQ(r.status, SolveStatus::converged) << r.message;
  ASSERT_EQ(r.columns.size(), 3u);
  for (const ColumnReport& c : r.columns) {
    EXPECT_EQ(c.reason, "CONVERGED_RTOL");
    EXPECT_LE(c.relative_residual, 1e-10);
    EXPECT_GT(c.iterations, 0);
    EXPECT_LT(c.iterations, 60);  // AMG: tens, not the hundreds of unpreconditioned CG
  }
  EXPECT_LE(relative_residual(A, B, X), 1e-10);
  EXPECT_LE(r.relative_residual, 1e-10);
  EXPECT_NEAR(r.relative_residual, relative_residual(A, B, X), 1e-12);
  EXPECT_LT(relative_difference(X, cholmod_solution(A, B)), 1e-8);
  EXPECT_EQ(r.preconditioner_setup, "new");
  ASSERT_FALSE(r.residuals.empty());
  EXPECT_LE(r.residuals.back(), 1e-10);
}

TEST(PetscSolver, BoomerAmgConverges) {
  SKIP_WITHOUT_PETSC();
  const SparseMatrix A = laplacian3d(12, 12, 12, 0.01);
  const Eigen::MatrixXd B = random_rhs(A.rows());
  PetscSolverOptions o;
  o.options = "-pc_type hypre -pc_hypre_type boomeramg";
  PetscSolver solver(o);
  EXPECT_EQ(solver.name(), "petsc-cg-hypre-boomeramg");
  ASSERT_EQ(solver.set_matrix(A).status, SolveStatus::converged);
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(A.rows(), 3);
  const SolveReport r = solver.solve(B, X);
  ASSERT_EQ(r.status, SolveStatus::converged) << r.message;
  EXPECT_LE(relative_residual(A, B, X), 1e-10);
  EXPECT_LT(relative_difference(X, cholmod_solution(A, B)), 1e-8);
}

TEST(PetscSolver, StoppedShortSaysSo) {
  SKIP_WITHOUT_PETSC();
  const SparseMatrix A = laplacian3d(10, 10, 10, 0.01);
  const Eigen::MatrixXd B = random_rhs(A.rows());
  PetscSolverOptions o;
  o.options = "-pc_type none -ksp_max_it 3";
  PetscSolver solver(o);
  ASSERT_EQ(solver.set_matrix(A).status, SolveStatus::converged);
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(A.rows(), 3);
  const SolveReport r = solver.solve(B, X);
  EXPECT_EQ(r.status, SolveStatus::max_iterations);
  EXPECT_NE(r.message.find("DIVERGED_ITS"), std::string::npos) << r.message;
  ASSERT_EQ(r.columns.size(), 3u);
  for (const ColumnReport& c : r.columns) {
    EXPECT_EQ(c.reason, "DIVERGED_ITS");
    EXPECT_EQ(c.iterations, 3);
    EXPECT_GT(c.relative_residual, 1e-6);
  }
  EXPECT_EQ(r.iterations, 9);
}

TEST(PetscSolver, BadOptionsAreRefusedNamingTheOption) {
  SKIP_WITHOUT_PETSC();
  EXPECT_NE(refusal("-ksp_type nosuchksp").find("nosuchksp"), std::string::npos)
      << refusal("-ksp_type nosuchksp");
  EXPECT_NE(refusal("-pc_type nosuchpc").find("nosuchpc"), std::string::npos);
  const std::string misspelt = refusal("-pc_gamg_thresold 0.05");
  EXPECT_NE(misspelt.find("-pc_gamg_thresold"), std::string::npos) << misspelt;
  EXPECT_NE(misspelt.find("solver.petsc_options"), std::string::npos) << misspelt;
  // An option of another preconditioner than the one chosen is one nothing reads.
  EXPECT_NE(refusal("-pc_type jacobi -pc_hypre_type boomeramg").find("-pc_hypre_type"),
            std::string::npos);
  // Options read only when the hierarchy is set up are found as read.
  EXPECT_EQ(refusal("-pc_gamg_threshold 0.02 -mg_levels_ksp_max_it 3"), "");
  EXPECT_EQ(refusal(""), "");
}

TEST(PetscSolver, TwoSolversKeepTheirOwnOptions) {
  SKIP_WITHOUT_PETSC();
  PetscSolverOptions jacobi;
  jacobi.options = "-ksp_type minres -pc_type jacobi";
  PetscSolver a(jacobi), b;
  EXPECT_EQ(a.name(), "petsc-minres-jacobi");
  EXPECT_EQ(b.name(), "petsc-cg-gamg");
  // And each really runs as named on a common matrix.
  const SparseMatrix A = laplacian3d(8, 8, 8, 0.1);
  const Eigen::MatrixXd B = random_rhs(A.rows());
  for (PetscSolver* s : {&a, &b}) {
    ASSERT_EQ(s->set_matrix(A).status, SolveStatus::converged);
    Eigen::MatrixXd X = Eigen::MatrixXd::Zero(A.rows(), 3);
    EXPECT_EQ(s->solve(B, X).status, SolveStatus::converged) << s->name();
    EXPECT_LE(relative_residual(A, B, X), 1e-9) << s->name();
  }
}

// A study makes a solver per cell in one process: each solver's options leave PETSc's options
// database (at most 512 entries) with it, so the hundredth is made as the first was.
TEST(PetscSolver, ManySolversInOneProcessDoNotFillTheOptionsDatabase) {
  SKIP_WITHOUT_PETSC();
  PetscSolverOptions boomer;
  boomer.options =
      "-pc_type hypre -pc_hypre_type boomeramg -pc_hypre_boomeramg_strong_threshold 0.5";
  for (int i = 0; i < 100; ++i) {
    ASSERT_NO_THROW(PetscSolver(i % 2 ? boomer : PetscSolverOptions{})) << "solver " << i;
  }
  PetscSolver last;
  const SparseMatrix A = laplacian3d(6, 6, 6, 0.1);
  const Eigen::MatrixXd B = random_rhs(A.rows());
  ASSERT_EQ(last.set_matrix(A).status, SolveStatus::converged);
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(A.rows(), 3);
  EXPECT_EQ(last.solve(B, X).status, SolveStatus::converged);
  EXPECT_LE(relative_residual(A, B, X), 1e-9);
}

TEST(PetscSolver, PatternHandedOverOnceAndValuesRefreshed) {
  SKIP_WITHOUT_PETSC();
  const SparseMatrix M = laplacian3d(9, 9, 9, 1.0, 4, 0.0);  // a diagonal on the 7-point pattern
  const SparseMatrix K = laplacian3d(9, 9, 9, 0.0, 4, 1.0);
  const Eigen::MatrixXd B = random_rhs(M.rows());
  PetscSolver solver;
  const std::uint64_t key = new_pattern_key();
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(M.rows(), 3);
  const char* expected[] = {"new", "refreshed", "kept"};
  const double dts[] = {1e-3, 2e-3, 2e-3};  // the last: values unchanged (heat flow's case)
  for (int step = 0; step < 3; ++step) {
    ASSERT_EQ(solver.set_matrix_sum(1.0, M, dts[step], K, {nullptr, nullptr, key}).status,
              SolveStatus::converged);
    const SolveReport r = solver.solve(B, X);
    ASSERT_EQ(r.status, SolveStatus::converged) << r.message;
    EXPECT_EQ(r.preconditioner_setup, expected[step]);
    SparseMatrix A = M + dts[step] * K;
    EXPECT_LE(relative_residual(A, B, X), 1e-10) << step;
  }
  EXPECT_EQ(solver.new_patterns(), 1);
  EXPECT_EQ(solver.preconditioner_setups(), 2);
  EXPECT_EQ(solver.pattern_comparisons(), 0);  // the key vouched
  // Another pattern: a new Mat and preconditioner.
  const SparseMatrix C = laplacian3d(7, 7, 7, 0.1);
  ASSERT_EQ(solver.set_matrix(C).status, SolveStatus::converged);
  const Eigen::MatrixXd BC = random_rhs(C.rows());
  Eigen::MatrixXd XC = Eigen::MatrixXd::Zero(C.rows(), 3);
  EXPECT_EQ(solver.solve(BC, XC).preconditioner_setup, "new");
  EXPECT_EQ(solver.new_patterns(), 2);
  EXPECT_LE(relative_residual(C, BC, XC), 1e-10);
}

TEST(PetscSolver, WarmStartAtTheSolutionNeedsNoIteration) {
  SKIP_WITHOUT_PETSC();
  const SparseMatrix A = laplacian3d(8, 8, 8, 0.1);
  const Eigen::MatrixXd B = random_rhs(A.rows());
  Eigen::MatrixXd X = cholmod_solution(A, B);
  PetscSolver solver;
  ASSERT_EQ(solver.set_matrix(A).status, SolveStatus::converged);
  const SolveReport r = solver.solve(B, X);
  EXPECT_EQ(r.status, SolveStatus::converged);
  EXPECT_LE(r.iterations, 3);
}

TEST(PetscSolver, SettingsRecordTheOptions) {
  SKIP_WITHOUT_PETSC();
  PetscSolverOptions o;
  o.options = "-pc_gamg_threshold 0.01";
  o.relative_tolerance = 1e-9;
  o.max_iterations = 500;
  PetscSolver solver(o);
  std::map<std::string, std::string> s;
  for (const auto& [k, v] : solver.settings()) s[k] = v;
  EXPECT_EQ(s["petsc_options"], "-pc_gamg_threshold 0.01");
  EXPECT_EQ(s["ksp_type"], "cg");
  EXPECT_EQ(s["pc_type"], "gamg");
  EXPECT_EQ(s["norm_type"], "UNPRECONDITIONED");  // CG on the true residual
  EXPECT_EQ(s["relative_tolerance"], "1.0000000000000001e-09");
  EXPECT_EQ(s["max_iterations"], "500");
  EXPECT_NE(s["preconditioner_reuse"].find("-pc_gamg_reuse_interpolation"), std::string::npos);
  EXPECT_NE(s["version"].find("PETSc"), std::string::npos);
}

}  // namespace
}  // namespace mcf
