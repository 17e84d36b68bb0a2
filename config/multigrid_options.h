#pragma once
// The geometric multigrid's cycle as a flow's solver config describes it: the options of the
// multigrid solver (config/solver_registry.h) and of CG's multigrid preconditioner
// (config/preconditioner_registry.h) alike, read in one place.

#include "config/config_values.h"
#include "solvers/multigrid.h"

namespace mcf {

/// The cycle, its count, smoothing, tolerance and Galerkin refresh of `config`.
MultigridOptions multigrid_options(const SolverConfig& config);

}  // namespace mcf
