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
  pcg_current_ = direct_current_ = false;
  return multigrid_.set_matrix(A, hierarchy);
}

SolveReport FallbackMultigridSolver::set_matrix_sum(const MatrixSum& sum, HierarchyView hierarchy) {
  pcg_current_ = direct_current_ = false;
  return multigrid_.set_matrix_sum(sum, hierarchy);
}

SolveReport FallbackMultigridSolver::solve_direct(const ConstMatrixRef& B, MatrixRef X,
                                                  SolveReport before, const std::string& why) {
  if (!direct_) direct_ = std::make_unique<CholmodSolver>(fallback_.direct_blas_threads);
  if (!direct_current_) {
    // The same pattern from step to step keeps the symbolic analysis (CholmodSolver compares).
    const SolveReport f = direct_->set_matrix(multigrid_.finest_matrix());
    if (!f.ok()) {
      SolveReport out = before;
      out.status = f.status;
      out.message = joined_messages(joined_messages(before.message, why),
                                    "the factorization failed: " + f.message);
      return out;
    }
    direct_current_ = true;
  }
  prefer_direct_ = true;
  ++direct_solves_;
  const SolveReport d = direct_->solve(B, X);
  SolveReport out = before;
  out.status = d.status;
  out.relative_residual = d.relative_residual;
  out.residuals.push_back(d.relative_residual);
  out.direct_fallback = true;
  out.message = joined_messages(joined_messages(before.message, why),
                                "a sparse Cholesky factorization solved it");
  out.message = joined_messages(out.message, d.message);
  return out;
}

SolveReport FallbackMultigridSolver::solve_in_place(const ConstMatrixRef& B, MatrixRef X) {
  SolveReport cycles = multigrid_.solve(B, X);
  const bool stalled = cycles.ok() && cycles.contraction > fallback_.stall_ratio &&
                       cycles.relative_residual > fallback_.tolerance;
  if (!stalled) return cycles;
  ++fallbacks_;
  char note[192];
  std::snprintf(note, sizeof note, "cycles stalled (contraction %.3g > %.3g)", cycles.contraction,
                fallback_.stall_ratio);
  cycles.message = joined_messages(cycles.message, note);
  const bool direct_allowed = fallback_.direct_after > 0;
  if (direct_allowed && prefer_direct_)
    return solve_direct(B, X, cycles, "an earlier stalled step needed the factorization");
  // r_k = r_0 · contraction^k, so healthy cycles would have reached r_k · (bound / contraction)^k.
  const double target =
      std::max(fallback_.tolerance,
               cycles.relative_residual *
                   std::pow(fallback_.stall_ratio / cycles.contraction, cycles.iterations));
  PcgOptions o;
  o.relative_tolerance = target;
  o.max_iterations = direct_allowed ? std::min(fallback_.max_iterations, fallback_.direct_after)
                                    : fallback_.max_iterations;
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
    const SolveReport m = pcg_->set_matrix(multigrid_.finest_matrix());
    if (!m.ok()) return m;
    pcg_current_ = true;
  }
  SolveReport cg = pcg_->solve(B, X);
  SolveReport out = cg;
  out.iterations = cycles.iterations + cg.iterations;
  out.fallback_iterations = cg.iterations;
  out.contraction = cycles.contraction;
  out.residuals = cycles.residuals;
  out.residuals.insert(out.residuals.end(), cg.residuals.begin(), cg.residuals.end());
  char took[128];
  std::snprintf(took, sizeof took, "CG preconditioned by the cycle took over to %.3g", target);
  out.message = joined_messages(joined_messages(cycles.message, took), cg.message);
  if (!direct_allowed || cg.status == SolveStatus::converged) return out;
  // CG broke down or ran out of its iterations: the factorization solves the step (it
  // overwrites X, whatever CG left there).
  return solve_direct(B, X, out, "CG did not reach it");
}

}  // namespace mcf
