#pragma once
// The solver axis: one row per linear solver `solver.name` selects (docs/extending.md "Adding a
// solver"). The flow, the config reader, the memory estimate and the command line read a solver's
// meaning from its row and nowhere else.

#include "config/config_values.h"
#include "config/memory_model.h"
#include "config/named_table.h"
#include "config/option_spec.h"
#include "solvers/linear_solver.h"
#include "solvers/multigrid.h"

#include <functional>
#include <memory>
#include <string>

namespace mcf {

struct SolverRow {
  std::string name;
  std::string help;  ///< one line for --help and docs/flow.md
  /// Makes the solver from the config's solver options. Throws std::invalid_argument for options
  /// it refuses (naming the option).
  std::function<std::unique_ptr<LinearSolver>(const SolverConfig&)> make;
  /// Bytes the solver adds beyond the basis's system matrix (a factor's fill, a hierarchy, a dense
  /// copy). Required: an estimate must never count a solver as free by omission.
  std::function<double(const SolverConfig&, const SystemFigures&)> memory;
  /// The options only this solver reads, keyed within "solver" ("stall_ratio"), read after the
  /// shared ones (solver_options()). Every config reads them; result.json records them only
  /// where this solver runs, so that the other solvers' cells keep the config keys
  /// (harness/cell_hash.h) they had before the option existed.
  std::vector<OptionSpec> options{};
  /// Starts from the warm start (the integrator's prediction) instead of solving exactly. Also
  /// what the octree basis sets its normal-gradient weight by (config/basis_registry.h).
  bool iterative = false;
  /// Uses solver.preconditioner (config/preconditioner_registry.h).
  bool uses_preconditioner = false;
  /// Needs the basis's geometric hierarchy (the hat basis builds its surface hierarchy then).
  bool needs_hierarchy = false;
  /// Factorizes with CHOLMOD, whose BLAS runs its own threads (`blas_threads`).
  bool uses_blas_threads = false;
  /// Runs on every MPI rank the harness was launched on (the others run on rank 0 alone).
  bool distributed = false;
  double default_tolerance = 1e-10;   ///< solver.tolerance when the config leaves it out
  int default_max_iterations = 1000;  ///< solver.max_iterations when the config leaves it out
};

/// Every solver, built-in ones first, in registration order.
const NamedTable<SolverRow>& solver_table();
/// Adds a solver. Throws std::logic_error for a row without a factory or a memory model, or a
/// name taken.
void register_solver(SolverRow row);
/// The row of `name`; std::invalid_argument ("unknown solver \"x\"") if there is none.
const SolverRow& solver_row(const std::string& name);

/// The options every solver shares, keyed from the top ("solver.name", "solver.tolerance",
/// "solver.max_iterations", "solver.preconditioner", "solver.cycle", "solver.cycles",
/// "solver.smooth"); result.json records them for every solver.
const std::vector<OptionSpec>& solver_options();
/// The solver option whose key within "solver" is `leaf` ("cycles", "petsc_options"): a shared
/// one or a row's own; std::logic_error if there is none.
const OptionSpec& solver_option(const std::string& leaf);
/// CG's preconditioner in `config` ("jacobi" where it sets none): a row of
/// config/preconditioner_registry.h, read where the solver row says uses_preconditioner.
std::string preconditioner_name(const SolverConfig& config);
/// Whether the config's solver (or its preconditioner) needs the basis's geometric hierarchy.
bool needs_hierarchy(const SolverConfig& config);
/// Whether the config's solver runs one flow divided across MPI ranks (distributed/): a row
/// marked `distributed` (petsc, multigrid), or CG with the multigrid preconditioner.
bool runs_across_ranks(const SolverConfig& config);
}  // namespace mcf
