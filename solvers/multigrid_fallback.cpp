#include "solvers/multigrid_fallback.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>

namespace mcf {
namespace {
/// Iterative refinement steps with the fallback's factor (solve_direct).
constexpr int kMaxRefinements = 3;
}  // namespace

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
  SolveReport d = direct_->solve(B, X);
  SolveReport out = before;
  out.direct_fallback = true;
  out.message = joined_messages(joined_messages(before.message, why),
                                "a sparse Cholesky factorization solved it");
  out.message = joined_messages(out.message, d.message);
  // Near a fold the factor of a nearly singular matrix can leave a residual above the bound:
  // iterative refinement with the same factor, X += A^{-1} (B - A X), while it helps.
  const double bound = fallback_.residual_bound;
  int refinements = 0;
  if (d.ok() && bound > 0 && d.relative_residual > bound) {
    const SparseMatrix& A = multigrid_.finest_matrix();
    Eigen::MatrixXd R(B.rows(), B.cols()), dX(B.rows(), B.cols());
    while (refinements < kMaxRefinements && d.relative_residual > bound) {
      R = B - A * X;
      const SolveReport c = direct_->solve(R, dX);
      if (!c.ok()) break;
      const Eigen::MatrixXd refined = X + dX;
      SolveReport r;
      report_true_residual(B, B - A * refined, r);
      if (!(r.relative_residual < d.relative_residual)) break;
      X = refined;
      d.relative_residual = r.relative_residual;
      ++refinements;
    }
  }
  out.status = d.status;
  out.relative_residual = d.relative_residual;
  out.residuals.push_back(d.relative_residual);
  if (refinements > 0) {
    char note[96];
    std::snprintf(note, sizeof note, "%d refinement step%s to %.3g", refinements,
                  refinements == 1 ? "" : "s", d.relative_residual);
    out.message = joined_messages(out.message, note);
  }
  if (d.ok() && bound > 0 && d.relative_residual > bound) {
    // Not converged to the bound, whatever the factorization says: the step goes on as the best
    // answer at hand and says so.
    out.status = SolveStatus::max_iterations;
    char note[128];
    std::snprintf(note, sizeof note, "the factorization's residual %.3g stays above the bound",
                  d.relative_residual);
    out.message = joined_messages(out.message, note);
  }
  return out;
}

namespace {
// The extra cycles' residuals, iterations and note appended to the report so far.
void append_cycles(SolveReport& out, const SolveReport& more) {
  out.residuals.insert(out.residuals.end(), more.residuals.begin(), more.residuals.end());
  out.iterations += more.iterations;
  out.extra_cycles += more.iterations;
  out.relative_residual = more.relative_residual;
  out.status = more.status;
  out.message = joined_messages(out.message, more.message);
}
}  // namespace

SolveReport FallbackMultigridSolver::solve_in_place(const ConstMatrixRef& B, MatrixRef X) {
  SolveReport cycles = multigrid_.solve(B, X);
  if (!cycles.ok()) return cycles;
  const double bound = fallback_.residual_bound;
  const double c = cycles.contraction;
  const bool reached_floor = cycles.relative_residual <= fallback_.tolerance;
  const bool stalled = fallback_.stall_ratio > 0 && c > fallback_.stall_ratio && !reached_floor;
  const bool above = bound > 0 && cycles.relative_residual > bound && !reached_floor;
  if (!stalled && !above) {
    // Fixed work checked against the bound (or down to the floor) is a converged step.
    if (bound > 0 || reached_floor) cycles.status = SolveStatus::converged;
    return cycles;
  }
  const double fit = start_fit();
  if (!stalled && !fallback_.bound_smooth_steps && fit >= kSmoothStartFit) {
    // A smooth stretch of the flow: the start fit the extrapolated motion and the cycles
    // contracted. The step keeps its fixed work, above the bound, and says so (the header's
    // "Smooth steps").
    char note[160];
    std::snprintf(note, sizeof note,
                  "cycles ended at %.3g, above the residual bound %.3g; kept: a smooth step (the "
                  "start fit the prediction at %.2f)",
                  cycles.relative_residual, bound, fit);
    cycles.status = SolveStatus::max_iterations;
    cycles.message = joined_messages(cycles.message, note);
    return cycles;
  }
  ++fallbacks_;
  char note[192];
  if (stalled)
    std::snprintf(note, sizeof note, "cycles stalled (contraction %.3g > %.3g)", c,
                  fallback_.stall_ratio);
  else
    std::snprintf(note, sizeof note, "cycles ended at %.3g, above the residual bound %.3g",
                  cycles.relative_residual, bound);
  cycles.message = joined_messages(cycles.message, note);
  const bool direct_allowed = fallback_.direct_after > 0;
  if (direct_allowed && prefer_direct_)
    return solve_direct(B, X, cycles, "an earlier step needed the factorization");

  SolveReport out = cycles;
  if (!stalled && c > 0 && c < 1) {
    // Contracting cycles that ended above the bound: r_{k+m} = r_k · c^m predicts m. A few more
    // cycles are cheaper than handing the step to CG (which copies the finest matrix); many are
    // not, since CG by the same cycle removes the slow modes that would make them many.
    //
    // The extra cycles are V-cycles with at most two sweeps each way, whatever the configured
    // cycle: what is left is typically a factor of a few to the bound, which a V(2,2)-cycle
    // covers at about a third of a W(5,5)-cycle's work, where another W(5,5)-cycle (contraction
    // ~0.01 on the hat hierarchy) would overshoot by two orders of magnitude.
    const int k = multigrid_.options().cycles;
    const double needed = std::ceil(std::log(bound / cycles.relative_residual) / std::log(c));
    if (needed <= std::max(2, k)) {
      const MultigridOptions kept = multigrid_.options();
      MultigridOptions more = kept;
      more.cycle = MultigridCycle::V;
      more.pre_smooth = std::min(kept.pre_smooth, kExtraCycleSweeps);
      more.post_smooth = std::min(kept.post_smooth, kExtraCycleSweeps);
      more.cycles = std::max(2, k);
      more.tolerance = bound;
      // A cycle that does not halve the residual: CG by the cycle does better from there.
      more.give_up_ratio = 0.5;
      multigrid_.set_options(more);
      const SolveReport extra = multigrid_.solve(B, X);
      multigrid_.set_options(kept);
      append_cycles(out, extra);
      if (!extra.ok()) return out;
      char took[128];
      std::snprintf(took, sizeof took, "%d more cycle%s ended at %.3g", extra.iterations,
                    extra.iterations == 1 ? "" : "s", extra.relative_residual);
      out.message = joined_messages(out.message, took);
      if (extra.status == SolveStatus::converged) return out;
    }
  }

  // CG by the cycle: to what healthy cycles would have reached (r_k = r_0 · c^k, so they would
  // be at r_k · (stall_ratio / c)^k) where the cycles stalled, and in any case to the bound.
  double target = std::numeric_limits<double>::infinity();
  if (stalled)
    target = cycles.relative_residual * std::pow(fallback_.stall_ratio / c, cycles.iterations);
  if (bound > 0) target = std::min(target, bound);
  target = std::max(fallback_.tolerance, target);
  PcgOptions o;
  o.relative_tolerance = target;
  o.max_iterations = direct_allowed ? std::min(fallback_.max_iterations, fallback_.direct_after)
                                    : fallback_.max_iterations;
  o.preconditioner = PcgPreconditioner::external;
  // Where the factorization follows, iterations that will not reach the target are wasted.
  o.give_up_off_course = direct_allowed;
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
  SolveReport before_cg = out;
  out = cg;
  out.iterations = before_cg.iterations + cg.iterations;
  out.extra_cycles = before_cg.extra_cycles;
  out.fallback_iterations = cg.iterations;
  out.contraction = cycles.contraction;
  out.residuals = before_cg.residuals;
  out.residuals.insert(out.residuals.end(), cg.residuals.begin(), cg.residuals.end());
  char took[128];
  std::snprintf(took, sizeof took, "CG preconditioned by the cycle took over to %.3g", target);
  out.message = joined_messages(joined_messages(before_cg.message, took), cg.message);
  if (!direct_allowed || cg.status == SolveStatus::converged) return out;
  // CG broke down or ran out of its iterations: the factorization solves the step (it
  // overwrites X, whatever CG left there).
  return solve_direct(B, X, out, "CG did not reach it");
}

}  // namespace mcf
