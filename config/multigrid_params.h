#pragma once
// The geometric multigrid's own options as config keys: the cycle's (the multigrid solver's and
// CG's multigrid preconditioner's alike, keys "solver.cycle", ...) and the stall guard's (the
// multigrid solver's, keys within "solver"). Their values live in SolverConfig::params
// (solver_param); each default is the numerics' own (MultigridOptions, StallFallbackOptions), so
// the reader, to_json, --help and the docs show one number. The solver and preconditioner tables
// (config/solver_registry.h, config/preconditioner_registry.h) add who owns them and read them
// back only through multigrid_options and stall_fallback_options.

#include "config/config_values.h"
#include "config/option_spec.h"
#include "solvers/multigrid_fallback.h"
#include "solvers/multigrid_options.h"

#include <vector>

namespace mcf {

/// The cycle's options, dotted from the top ("solver.cycle", "solver.cycles", "solver.smooth",
/// "solver.galerkin_by_term", "solver.precision", "solver.galerkin_refresh"), without their owner.
const std::vector<OptionSpec>& multigrid_cycle_options();
/// The stall guard's options, keyed within "solver" ("stall_ratio", "residual_bound",
/// "bound_smooth_steps", "fallback_tolerance", "direct_after").
const std::vector<OptionSpec>& stall_guard_options();

/// The cycle of `config` (its cycle, count, smoothing, tolerance and Galerkin refresh).
MultigridOptions multigrid_options(const SolverConfig& config);
/// The stall guard of `config` (also its iteration cap and CHOLMOD's threads).
StallFallbackOptions stall_fallback_options(const SolverConfig& config);

}  // namespace mcf
