#pragma once
// A multigrid solve that does not return a silently inexact answer: a fixed number k of cycles a
// step (the fast setting) promises to reduce the step's initial residual r_0 by at least
// stall_ratio^k. When the cycles stall — their mean reduction per cycle is worse than the bound, as
// on the paper's octree system or a surface whose triangles degenerate during the flow — the solve
// goes on with CG preconditioned by the same cycle, from the cycles' iterate, until the residual is
// what healthy cycles would have reached, r_0 · stall_ratio^k (never below `tolerance`). Krylov
// acceleration removes the few slow modes (error-propagation eigenvalues near 1) that stall a
// cycle in a few iterations, so the step is as accurate as a step of contracting cycles at a few
// more cycles' cost. Solving to a fixed small tolerance instead can cost a thousand iterations on a
// nearly degenerate mesh, for no accuracy the flow can see.
//
// CG is not the last resort. Where the surface degenerates, the cycle loses its grip on more and
// more modes and CG by the cycle needs tens, then hundreds of iterations; near a fold, with
// cotangent weights many orders above the mass, p^T A p can even round to a non-positive number
// although the matrix is positive definite, and CG breaks down. So CG gets `direct_after`
// iterations: when it has not reached its target by then, or breaks down earlier, the step is
// solved by a sparse Cholesky factorization (CHOLMOD) of the same matrix, and every later stalled
// step of this solver goes to the factorization straight after its cycles (a flow that degenerates
// does not recover). The factorization's symbolic analysis is kept while the pattern stays. Where
// the matrix is not positive definite to working precision either, the factorization says so, and
// the step fails as a CHOLMOD flow's would.
//
// The fallback costs nothing on a step whose cycles contract but one residual pass (to know the
// contraction); CG and the factorization read the finest matrix in the caller's numbering, which
// the multigrid lays out at the first stall and refreshes in place after (finest_matrix()).

#include "solvers/cholmod_solver.h"
#include "solvers/multigrid.h"
#include "solvers/pcg_solver.h"

#include <memory>

namespace mcf {

struct StallFallbackOptions {
  /// Fall back when the cycles' mean contraction (SolveReport::contraction) exceeds this; CG then
  /// stops at r_0 · stall_ratio^k.
  double stall_ratio = 0.2;
  double tolerance = 1e-10;  ///< the fallback CG never stops below this relative residual
  int max_iterations = 1000;
  /// CG iterations after which a stalled step goes to the factorization (also at once on a
  /// breakdown); 0 = never (CG runs to max_iterations and a breakdown fails the step).
  int direct_after = 10;
  int direct_blas_threads = kKeepBlasThreads;  ///< the factorization's OpenBLAS threads
};

class FallbackMultigridSolver final : public LinearSolver {
 public:
  FallbackMultigridSolver(MultigridOptions cycles, StallFallbackOptions fallback);
  std::string name() const override { return multigrid_.name() + "+fallback"; }
  SolveReport set_matrix(const SparseMatrix& A, HierarchyView hierarchy = {}) override;
  SolveReport set_matrix_sum(const MatrixSum& sum, HierarchyView hierarchy = {}) override;
  using LinearSolver::set_matrix_sum;
  int fallbacks() const { return fallbacks_; }  ///< solves that fell back since construction
  /// Solves that the factorization finished since construction.
  int direct_solves() const { return direct_solves_; }

 protected:
  /// The cycles; then, if they stalled and have not reached the fallback tolerance, CG; then,
  /// if CG broke down or did not reach its target in `direct_after` iterations, the
  /// factorization. The report lists the cycles' residuals followed by CG's, `iterations` counts
  /// both, `fallback_iterations` CG's and `direct_fallback` says whether the factorization gave
  /// the answer; its status is that of the last solver to run (max_iterations when CG ran out
  /// with no factorization allowed).
  SolveReport solve_in_place(const ConstMatrixRef& B, MatrixRef X) override;

 private:
  MultigridSolver multigrid_;
  StallFallbackOptions fallback_;
  std::unique_ptr<PcgSolver> pcg_;
  bool pcg_current_ = false;  ///< pcg_ holds the multigrid's present finest matrix
  std::unique_ptr<CholmodSolver> direct_;
  bool direct_current_ = false;  ///< direct_ holds the factor of the present finest matrix
  bool prefer_direct_ = false;  ///< a step went to the factorization: later stalled ones do at once
  int fallbacks_ = 0;
  int direct_solves_ = 0;

  /// Solves B by the factorization into X; `before` is what ran first (cycles, CG).
  SolveReport solve_direct(const ConstMatrixRef& B, MatrixRef X, SolveReport before,
                           const std::string& why);
};

}  // namespace mcf
