#include "config/multigrid_params.h"

namespace mcf {
namespace {

// The numerics' defaults, the one source of every default below.
const MultigridOptions kCycle{};
const StallFallbackOptions kGuard{};

std::vector<OptionSpec> cycle_options() {
  OptionSpec cycle =
      solver_param(option("solver.cycle", OptionType::string, to_string(kCycle.cycle), "--cycle",
                          "Multigrid cycle (solver and preconditioner)"));
  cycle.choices = [] { return std::vector<Choice>{{"V", ""}, {"W", ""}}; };
  OptionSpec cycles =
      ranged(solver_param(option("solver.cycles", OptionType::integer, kCycle.cycles, "--cycles",
                                 "Multigrid cycles per solve")),
             1, 10000);
  OptionSpec smooth = ranged(
      solver_param(option("solver.smooth", OptionType::integer, kCycle.pre_smooth, "--smooth",
                          "Gauss-Seidel sweeps before and after each coarse correction")),
      0, 1000);
  OptionSpec by_term = solver_param(option(
      "solver.galerkin_by_term", OptionType::boolean, kCycle.galerkin_by_term, "--galerkin-by-term",
      "Multigrid: refresh the coarse operators term by term, only the terms whose "
      "values changed (cMCF: the mass alone); equal to the sum's products up to "
      "rounding"));
  by_term.flag_kind = FlagKind::set_true;
  OptionSpec precision = solver_param(
      option("solver.precision", OptionType::string, kCycle.mixed_precision ? "mixed" : "double",
             "--precision",
             "Multigrid: the finest level's sweeps in double or in single precision inside "
             "a double-precision residual correction (same solution, fewer bytes a sweep)"));
  precision.choices = [] {
    return std::vector<Choice>{{"double", "every sweep in double precision"},
                               {"mixed", "the finest sweeps read a single-precision copy"}};
  };
  OptionSpec refresh =
      ranged(solver_param(
                 option("solver.galerkin_refresh", OptionType::integer, kCycle.galerkin_refresh,
                        "--galerkin-refresh",
                        "Multigrid: recompute the coarse operators on every k-th step only (the "
                        "finest level, hence the solution, stays exact; the coarse corrections use "
                        "operators up to k - 1 steps old)")),
             1, 1000);
  // Added after the first results: recorded only when set, so that cells of earlier runs keep
  // their config keys (harness/cell_hash.h).
  for (OptionSpec* later : {&by_term, &precision, &refresh}) later->recorded = Recorded::when_set;
  return {cycle, cycles, smooth, by_term, precision, refresh};
}

std::vector<OptionSpec> guard_options() {
  OptionSpec bound_smooth_steps = solver_param(option(
      "bound_smooth_steps", OptionType::boolean, kGuard.bound_smooth_steps, "--bound-smooth-steps",
      "Multigrid: hold smooth steps to the residual bound too; by default "
      "a step whose start fit the integrator's prediction (theta >= 0.5) "
      "and whose cycles contracted keeps its fixed work above the bound "
      "and says so"));
  bound_smooth_steps.flag_kind = FlagKind::set_true;
  return {
      ranged(solver_param(
                 option("stall_ratio", OptionType::number, kGuard.stall_ratio, "--stall-ratio",
                        "Multigrid: where the cycles reduce the residual by less than this per "
                        "cycle, CG preconditioned by the cycle takes over until they have reached "
                        "what this ratio promises (or the residual bound); 0 = never")),
             0, 1),
      ranged(solver_param(option(
                 "residual_bound", OptionType::number, kGuard.residual_bound, "--residual-bound",
                 "Multigrid: a step is converged only at or below this relative residual; "
                 "one whose cycles end above it continues with more cycles, then CG "
                 "preconditioned by the cycle, then the factorization; 0 = no bound")),
             0, 1),
      bound_smooth_steps,
      ranged(solver_param(option(
                 "fallback_tolerance", OptionType::number, kGuard.tolerance, "--fallback-tolerance",
                 "Multigrid: the fallback CG never stops below this relative residual")),
             1e-300, 1),
      ranged(solver_param(
                 option("direct_after", OptionType::integer, kGuard.direct_after, "--direct-after",
                        "Multigrid: when the fallback CG has not reached its target after this "
                        "many iterations, or breaks down, a sparse Cholesky factorization solves "
                        "the step, and later steps that need more than their cycles at once; "
                        "0 = never")),
             0, 1000000)};
}

/// The value in `c` of the option of `options` called `leaf` (a name this file defines).
template <class T>
T value(const SolverConfig& c, const std::vector<OptionSpec>& options, const std::string& leaf) {
  const OptionSpec* o = find_option(options, leaf);
  if (!o) throw std::logic_error("multigrid_params: no option \"" + leaf + "\"");
  return param_value(c, *o).get<T>();
}

}  // namespace

const std::vector<OptionSpec>& multigrid_cycle_options() {
  static const std::vector<OptionSpec> options = cycle_options();
  return options;
}

const std::vector<OptionSpec>& stall_guard_options() {
  static const std::vector<OptionSpec> options = guard_options();
  return options;
}

MultigridOptions multigrid_options(const SolverConfig& c) {
  const auto& cycle = multigrid_cycle_options();
  MultigridOptions o;
  o.cycle = value<std::string>(c, cycle, "cycle") == "V" ? MultigridCycle::V : MultigridCycle::W;
  o.cycles = value<int>(c, cycle, "cycles");
  o.pre_smooth = o.post_smooth = value<int>(c, cycle, "smooth");
  o.tolerance = c.tolerance;
  o.galerkin_by_term = value<bool>(c, cycle, "galerkin_by_term");
  o.mixed_precision = value<std::string>(c, cycle, "precision") == "mixed";
  o.galerkin_refresh = value<int>(c, cycle, "galerkin_refresh");
  return o;
}

StallFallbackOptions stall_fallback_options(const SolverConfig& c) {
  const auto& guard = stall_guard_options();
  StallFallbackOptions f;
  f.stall_ratio = value<double>(c, guard, "stall_ratio");
  f.residual_bound = value<double>(c, guard, "residual_bound");
  f.bound_smooth_steps = value<bool>(c, guard, "bound_smooth_steps");
  f.tolerance = value<double>(c, guard, "fallback_tolerance");
  f.max_iterations = c.max_iterations;
  f.direct_after = value<int>(c, guard, "direct_after");
  f.direct_blas_threads = c.blas_threads;
  return f;
}

}  // namespace mcf
