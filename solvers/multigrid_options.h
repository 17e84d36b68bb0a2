#pragma once
// What a caller of the multigrid solver (solvers/multigrid.h) chooses and reads back beside the
// solver itself: the cycle's shape and counts (MultigridOptions) and the work its cycles did per
// level (MultigridLevelWork). In a header of their own so that the solver's internal parts
// (solvers/multigrid_state.h) can read them without including the solver's class, which in turn
// holds those parts.

#include <cstdint>

namespace mcf {

enum class MultigridCycle { V, W };

inline const char* to_string(MultigridCycle c) {
  return c == MultigridCycle::V ? "V" : "W";
}

/// Where a solver's cycles spent their time, per level: how often the cycle visited the level
/// and the wall time spent on the level itself (its smoothing sweeps, residual, restriction and
/// prolongation; on the coarsest level the direct solve), not counting the coarser levels it
/// recursed into. A W-cycle visits level l (below the finest) 2^(finest - l) times, the coarsest
/// level as often as the next one, so the small levels' share of its time is measured, not
/// estimated.
struct MultigridLevelWork {
  std::int64_t visits = 0;
  double seconds = 0.0;
};

struct MultigridOptions {
  MultigridCycle cycle = MultigridCycle::W;
  int cycles = 1;       ///< cycles per solve, at least 1 (the cap when tolerance > 0)
  int pre_smooth = 5;   ///< Gauss-Seidel sweeps before the coarse correction, per level
  int post_smooth = 5;  ///< Gauss-Seidel sweeps after the coarse correction, per level
  /// 0: run exactly `cycles` cycles (status max_iterations: nothing checked where they ended);
  /// > 0: stop early once the relative residual is below (status converged).
  double tolerance = 0.0;
  /// With a tolerance: stop early (status max_iterations) after a cycle that reduces the relative
  /// residual by less than this factor, where more cycles would waste the time that a better
  /// solver (CG by the cycle) then has; 0 = never.
  double give_up_ratio = 0.0;
  /// Measure the warm start's residual (one residual pass) so that the report's contraction is
  /// known even when `tolerance` is 0; with a tolerance it is measured anyway.
  bool measure_contraction = false;
  /// Galerkin refresh by term (set_matrix_sum with a hierarchy; docs/surface-multigrid.md): each
  /// level keeps the coarse operators of the sum's terms, Pᵀ M P, Pᵀ K P (and Pᵀ S P), and a call
  /// recomputes only those of a term whose values changed since the previous call (compared
  /// bitwise with a kept copy), then A_l = a M_l + b K_l [+ s S_l] entry by entry. cMCF changes
  /// only M, the heat flow nothing. The finest level is the sum itself, as without the option, so
  /// the residual and the solution the cycles converge to are the same; the coarse operators equal
  /// the Galerkin products of the sum up to rounding only (linearity, not bitwise). Costs one
  /// copy of each term's values per level.
  bool galerkin_by_term = false;
  /// Mixed precision (docs/surface-multigrid.md "Options"): the finest level's sweeps read its
  /// off-diagonal entries in single precision too (6 bytes an entry instead of 10), and solve()
  /// runs each cycle on the correction: e = cycle(r) from e = 0 with r = b - A x in double
  /// precision (the residual that the previous cycle's convergence check computed, kept), then
  /// x += e. The fixed point is the solution of A x = b, as in double precision; only the
  /// contraction per cycle may change. precondition() is a cycle from zero anyway.
  bool mixed_precision = false;
  /// Lagged Galerkin refresh: with k > 1, a set_matrix on the pattern already set up recomputes
  /// the coarse operators (Galerkin products, coarsest factorization) only on every k-th call;
  /// in between only the finest level takes the new values. The finest residual, sweeps and
  /// hence the solution the cycles converge to are exact; only the coarse correction uses
  /// operators up to k - 1 calls old (still symmetric positive definite, so the cycle stays a
  /// valid preconditioner), which may cost contraction per cycle. A new pattern, a failed call,
  /// galerkin_by_term or a single level always refreshes. 1: every call (the default).
  int galerkin_refresh = 1;
};

}  // namespace mcf
