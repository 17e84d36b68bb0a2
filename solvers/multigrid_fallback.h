#pragma once
// A multigrid solve that does not return a silently inexact answer: a fixed number of cycles a
// step (the fast setting), and when those cycles stall — their mean residual reduction per cycle
// is worse than a bound, as on a surface whose triangles degenerate during the flow — the solve
// goes on with CG preconditioned by the same cycle, from the cycles' iterate, to a tolerance.
// Krylov acceleration keeps converging where the cycle's error propagation has an eigenvalue
// near 1 (a few slow modes), since CG removes those modes in a few iterations.
//
// The fallback costs nothing on a step whose cycles contract but one residual pass (to know the
// contraction); its CG takes a copy of the finest matrix from the multigrid only when it runs.

#include "solvers/multigrid.h"
#include "solvers/pcg_solver.h"

#include <memory>

namespace mcf {

struct StallFallbackOptions {
  /// Fall back when the cycles' mean contraction (SolveReport::contraction) exceeds this.
  double stall_ratio = 0.5;
  double tolerance = 1e-10;  ///< the fallback CG's relative residual
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
