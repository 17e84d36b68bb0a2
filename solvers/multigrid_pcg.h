#pragma once
// PCG preconditioned by one multigrid cycle (V or W, symmetric smoothing): the robustness of
// Krylov acceleration with the multigrid hierarchy doing the work.

#include "solvers/multigrid.h"
#include "solvers/pcg_solver.h"

namespace mcf {

class MultigridPcgSolver final : public LinearSolver {
 public:
  MultigridPcgSolver(MultigridOptions cycle, PcgOptions pcg);
  std::string name() const override { return "pcg-" + multigrid_.name(); }
  SolveReport set_matrix(const SparseMatrix& A, HierarchyView hierarchy = {}) override;
  /// Both halves take M and K (each keeps its one copy of the sum).
  SolveReport set_matrix_sum(const MatrixSum& sum, HierarchyView hierarchy = {}) override;
  using LinearSolver::set_matrix_sum;

 protected:
  SolveReport solve_in_place(const ConstMatrixRef& B, MatrixRef X) override {
    return pcg_.solve(B, X);
  }

 private:
  MultigridSolver multigrid_;
  PcgSolver pcg_;
};

}  // namespace mcf
