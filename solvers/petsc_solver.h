#pragma once
// PETSc's Krylov methods and preconditioners behind the LinearSolver interface (docs/petsc.md).
// The default is the baseline of Chuang & Kazhdan (2011): conjugate gradients preconditioned by
// smoothed-aggregation algebraic multigrid (PETSc's GAMG), relative residual 1e-10, at most 3000
// iterations. Any KSP/PC combination PETSc has is one options string away
// (`-pc_type hypre -pc_hypre_type boomeramg`, `-ksp_type minres -pc_type jacobi`, ...).
//
// The matrix is handed to one PETSc Mat per sparsity pattern (AIJ, the pattern allocated once)
// and only its values are rewritten on later calls with that pattern, so a preconditioner that
// can keep its structure does (GAMG's -pc_gamg_reuse_interpolation, on by default here); values
// bitwise equal to the previous call's leave the Mat untouched and the whole preconditioner is
// kept (KSPSetReusePreconditioner; heat flow's system never changes). The three coordinates are
// solved one after another by the same KSP, each from its warm start.
//
// Under mpirun (PETSC_COMM_WORLD of several ranks) every rank runs the whole flow and holds the
// whole system; the Mat is then an MPIAIJ of which each rank holds its block of rows, and each
// solution is gathered back to every rank (docs/petsc.md, "Across MPI ranks").
//
// PETSc headers stay inside petsc_solver.cpp: this header compiles without PETSc, and in a build
// without it the constructor throws PetscUnavailable.

#include "solvers/linear_solver.h"

#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace mcf {

struct PetscSolverOptions {
  /// PETSc options as on PETSc's command line ("-ksp_type minres -pc_type hypre"), inserted
  /// after the defaults (so they override them) under this solver's own prefix.
  std::string options;
  double relative_tolerance = 1e-10;  ///< -ksp_rtol of the defaults
  int max_iterations = 3000;          ///< -ksp_max_it of the defaults
};

/// The options every PETSc solver starts from, before the user's: CG, GAMG keeping its
/// interpolation while the pattern stays, Richardson with symmetric SOR on its levels, the warm
/// start used, and the tolerance and iteration cap. CG is then set to test the true
/// (unpreconditioned) residual unless -ksp_norm_type is given, so that the tolerance means
/// ||b - A x|| / ||b|| as for the other solvers.
std::string petsc_default_options(double relative_tolerance, int max_iterations);

class PetscSolver final : public LinearSolver {
 public:
  /// Starts PETSc (PetscRuntime) and checks the options before any flow uses them: a KSP with
  /// them set up and run on a small Laplacian (48 x 48 grid), after which every option the user
  /// gave must have been read. Throws std::invalid_argument naming the option (an unknown
  /// -ksp_type/-pc_type value, an option nothing read, a combination PETSc refuses), and
  /// PetscUnavailable in a build without PETSc.
  explicit PetscSolver(PetscSolverOptions options = {});
  ~PetscSolver() override;
  PetscSolver(const PetscSolver&) = delete;
  PetscSolver& operator=(const PetscSolver&) = delete;

  /// "petsc-<ksp>-<pc>", e.g. "petsc-cg-gamg".
  std::string name() const override;

  /// Copies A into the Mat: a new pattern (size, nonzeros, or indices: compared unless
  /// hierarchy.pattern_key vouches for it) makes a new Mat and a new preconditioner; the same
  /// pattern rewrites the values only. The hierarchy's prolongations are not used (algebraic
  /// multigrid builds its own).
  SolveReport set_matrix(const SparseMatrix& A, HierarchyView hierarchy = {}) override;
  /// a M + b K [+ s S] on one pattern, formed straight into the Mat's value array.
  SolveReport set_matrix_sum(const MatrixSum& sum, HierarchyView hierarchy = {}) override;
  using LinearSolver::set_matrix_sum;

  /// What the solver runs as, for result.json's "solver_settings": the options as given and as
  /// inserted (defaults first), the KSP and PC types, tolerances, and the preconditioner reuse.
  std::vector<std::pair<std::string, std::string>> settings() const override;

  /// Preconditioner set-ups (PCSetUp) so far, and how many of them had a new pattern.
  int preconditioner_setups() const;
  int new_patterns() const;
  /// Index-by-index pattern comparisons made so far.
  int pattern_comparisons() const;

  /// "PETSc 3.18.5"; "" without PETSc.
  static std::string version();

 protected:
  /// Solves the columns of B one after another from X's values. Reports per column the KSP's
  /// iterations, the true relative residual and the converged reason; iterations is their sum,
  /// relative_residual the worst. A column whose KSP did not converge makes the status
  /// max_iterations (DIVERGED_ITS), not_positive_definite (DIVERGED_INDEFINITE_*),
  /// numerical_issue (DIVERGED_NANORINF) or failed (any other reason), with the reason named in
  /// the message: never a silently inexact answer.
  SolveReport solve_in_place(const ConstMatrixRef& B, MatrixRef X) override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mcf
