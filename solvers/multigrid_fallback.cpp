#include "solvers/multigrid_fallback.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

namespace mcf {

FallbackMultigridSolver::FallbackMultigridSolver(MultigridOptions cycles,
                                                 StallFallbackOptions fallback)
    : multigrid_([&] {
        cycles.measure_contraction = true;
        return cycles;
      }()),
      fallback_(fallback) {}

SolveReport FallbackMultigridSolver::set_matrix(const SparseMatrix& A, HierarchyView hierarchy) {
  pcg_current_ = false;
  return multigrid_.set_matrix(A, hierarchy);
}

SolveReport FallbackMultigridSolver::set_matrix_sum(const MatrixSum& sum, HierarchyView hierarchy) {
  pcg_current_ = false;
  return multigrid_.set_matrix_sum(sum, hierarchy);
}

SolveReport FallbackMultigridSolver::solve_in_place(const ConstMatrixRef& B, MatrixRef X) {
  SolveReport cycles = multigrid_.solve(B, X);
  const bool stalled = cycles.ok() && cycles.contraction > fallback_.stall_ratio &&
                       cycles.relative_residual > fallback_.tolerance;
  if (!stalled) return cycles;
  // r_k = r_0 · contraction^k, so healthy cycles would have reached r_k · (bound / contraction)^k.
  const double target =
      std::max(fallback_.tolerance,
               cycles.relative_residual *
                   std::pow(fallback_.stall_ratio / cycles.contraction, cycles.iterations));
  PcgOptions o;
  o.relative_tolerance = target;
  o.max_iterations = fallback_.max_iterations;
  o.preconditioner = PcgPreconditioner::external;
  if (!pcg_) {
    pcg_ = std::make_unique<PcgSolver>(o);
    // One cycle from zero with equal sweeps before and after: a symmetric operator
    // (MultigridSolver::precondition), as CG needs.
    pcg_->set_preconditioner(
        [this](const Eigen::MatrixXd& r, Eigen::MatrixXd& z) { multigrid_.precondition(r, z); });
  }
  pcg_->set_options(o);
  if (!pcg_current_) {
    const SolveReport m = pcg_->set_matrix(multigrid_.level_matrix(multigrid_.levels() - 1));
    if (!m.ok()) return m;
    pcg_current_ = true;
  }
  ++fallbacks_;
  SolveReport cg = pcg_->solve(B, X);
  SolveReport out = cg;
  out.iterations = cycles.iterations + cg.iterations;
  out.fallback_iterations = cg.iterations;
  out.contraction = cycles.contraction;
  out.residuals = cycles.residuals;
  out.residuals.insert(out.residuals.end(), cg.residuals.begin(), cg.residuals.end());
  char note[192];
  std::snprintf(
      note, sizeof note,
      "cycles stalled (contraction %.3g > %.3g): CG preconditioned by the cycle took over to %.3g",
      cycles.contraction, fallback_.stall_ratio, target);
  out.message = cycles.message.empty() ? note : cycles.message + "; " + note;
  if (!cg.message.empty()) out.message += "; " + cg.message;
  return out;
}

}  // namespace mcf
