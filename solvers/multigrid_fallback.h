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
// The fallback costs nothing on a step whose cycles contract but one residual pass (to know the
// contraction); its CG takes a copy of the finest matrix from the multigrid only when it runs.

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
};

class FallbackMultigridSolver final : public LinearSolver {
 public:
  FallbackMultigridSolver(MultigridOptions cycles, StallFallbackOptions fallback);
  std::string name() const override { return multigrid_.name() + "+fallback"; }
  SolveReport set_matrix(const SparseMatrix& A, HierarchyView hierarchy = {}) override;
  SolveReport set_matrix_sum(const MatrixSum& sum, HierarchyView hierarchy = {}) override;
  using LinearSolver::set_matrix_sum;
  int fallbacks() const { return fallbacks_; }  ///< solves that fell back since construction

 protected:
  /// The cycles; then, if they stalled and have not reached the fallback tolerance, CG. The
  /// report lists the cycles' residuals followed by CG's, `iterations` counts both, and
  /// `fallback_iterations` CG's; its status is CG's (max_iterations when CG too ran out).
  SolveReport solve_in_place(const ConstMatrixRef& B, MatrixRef X) override;

 private:
  MultigridSolver multigrid_;
  StallFallbackOptions fallback_;
  std::unique_ptr<PcgSolver> pcg_;
  bool pcg_current_ = false;  ///< pcg_ holds the multigrid's present finest matrix
  int fallbacks_ = 0;
};

}  // namespace mcf
