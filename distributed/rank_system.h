#pragma once
// The hat basis's system on one rank of a distributed flow (distributed/rank_mesh.h): the rank
// assembles the rows of M and K it owns from its own triangles — complete, since it holds every
// triangle around an owned vertex —, writes them into PETSc's distributed matrix (the pattern
// preallocated once, the values refreshed in place), exchanges the ghost ring of an iterate
// after each solve (a ghosted PETSc vector, block size 3), and solves (a M + b K) Y = R across
// the ranks. No rank ever holds more than its own rows.
//
// Held functions (the vertices of an open boundary, docs/design.md "Conventions") are eliminated
// symmetrically, as the one-process flow's reduced system does (steps/reduced_system.h): their
// values are moved to the right-hand side, their rows and columns replaced by the identity.
//
// Solvers: "petsc" — PETSc's KSP with the one-process solver's defaults (CG, GAMG, symmetric SOR
// smoothing; solvers/petsc_solver.h) and the user's options over them; "multigrid" — the surface
// multigrid across ranks on the three coordinates together (distributed/rank_multigrid.h); "pcg"
// with the multigrid preconditioner — CG preconditioned by one such cycle, three columns at once
// (distributed/rank_block_cg.h). A guarded step's last resort is PETSc's Cholesky with MUMPS.
//
// PETSc's headers stay in rank_system.cpp; without PETSc the constructor throws PetscUnavailable.

#include "bases/hat_basis.h"
#include "distributed/rank_mesh.h"
#include "solvers/linear_solver.h"

#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace mcf::dist {

struct RankSolverOptions {
  std::string solver = "petsc";  ///< petsc | multigrid | pcg (preconditioner multigrid)
  std::string petsc_options;     ///< PETSc options over the defaults (solver "petsc")
  double tolerance = 1e-10;      ///< relative residual; 0 with "multigrid": run `cycles` cycles
  int max_iterations = 3000;
  // The surface multigrid's cycle (solver "multigrid" and the "pcg" preconditioner).
  std::string cycle = "W";
  int cycles = 1;
  int smooth = 5;
  /// "multigrid" with fixed cycles: a step ending above this relative residual goes on with CG
  /// preconditioned by the cycle to it, then a distributed factorization (MUMPS); 0 = no bound
  /// (solvers/multigrid_fallback.h is the one-process guard).
  double residual_bound = 1e-4;
  /// Hold smooth steps (start fit >= kSmoothStartFit, solvers/multigrid_fallback.h) to the bound
  /// too; by default such a step keeps its cycles above it and says so.
  bool bound_smooth_steps = false;
  int direct_after = 10;
};

class RankSystem {
 public:
  RankSystem(const RankMesh& mesh, MassKind mass, RankSolverOptions options);
  ~RankSystem();
  RankSystem(const RankSystem&) = delete;
  RankSystem& operator=(const RankSystem&) = delete;

  /// The owned rows with their ghosts appended (local numbering), from the owned rows of every
  /// rank: collective.
  Positions with_ghosts(const Coefficients& owned);
  /// Re-integrates M and/or K at the local positions (owned and ghosts).
  void update(const Positions& local, bool mass, bool stiffness);
  /// The owned rows of M X and K X: collective (X's ghost rows are exchanged first).
  Coefficients apply_mass(const Coefficients& owned);
  Coefficients apply_stiffness(const Coefficients& owned);
  /// The owned rows of (a M + b K) X, with one ghost exchange: collective.
  Coefficients apply_sum(double a, double b, const Coefficients& owned);
  /// Solves (a M + b K) Y = R on the owned rows, from `warm`, with the held rows at `held`.
  /// `start_fit`: how well `warm` fit a prediction (LinearSolver::set_start_fit; negative: none).
  /// Collective. The report is the same on every rank.
  SolveReport solve(double a, double b, const Coefficients& R, const Coefficients& held,
                    const Coefficients& warm, Coefficients& Y, double start_fit = -1);

  /// Owned functions held by the boundary (local numbers), and their count over all ranks.
  const std::vector<int>& held() const { return held_; }
  std::int64_t held_global() const { return held_global_; }
  /// The KSP and PC as PETSc reports them, and the options inserted ("solver_settings").
  std::vector<std::pair<std::string, std::string>> settings() const;
  std::string name() const;
  /// Levels of the surface multigrid across ranks (1 without one).
  int levels() const;
  /// Bytes this rank holds of PETSc's matrix and of the preconditioner's hierarchy (-1 where
  /// the PC is not PETSc's multigrid).
  double matrix_bytes() const;
  double preconditioner_bytes() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::vector<int> held_;
  std::int64_t held_global_ = 0;
};

}  // namespace mcf::dist
