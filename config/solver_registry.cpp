#include "config/solver_registry.h"

#include "config/config_reader.h"
#include "config/multigrid_params.h"
#include "config/preconditioner_registry.h"
#include "solvers/cholmod_solver.h"
#include "solvers/dense_reference.h"
#include "solvers/multigrid_fallback.h"
#include "solvers/petsc_solver.h"

#include <stdexcept>

namespace mcf {
namespace {

// The dense matrix and its LLT, 8 bytes an entry each.
constexpr double kDensePerUnknown2 = 16;

// PETSc (solvers/petsc_solver.h): a model, not a fit. Its AIJ copy of the system costs 12 bytes a
// nonzero (value and column index) and the set-up copies of the values and indices 12 more; the
// smoothed-aggregation hierarchy (GAMG, BoomerAMG) and its Galerkin products add about twice the
// finest matrix again, so 3 matrices in all; and the KSP's vectors (CG's four, the three of the
// solve, the hierarchy's smoothers') about 16 doubles per unknown.
constexpr double kPetscMatrixCopies = 3;
constexpr double kPetscBytesPerNonzero = 12 + 12.0 / kPetscMatrixCopies;
constexpr double kPetscVectorBytesPerUnknown = 16 * 8;

std::unique_ptr<LinearSolver> make_multigrid(const SolverConfig& c) {
  const StallFallbackOptions f = stall_fallback_options(c);
  if (f.stall_ratio <= 0 && f.residual_bound <= 0)
    return std::make_unique<MultigridSolver>(multigrid_options(c));
  return std::make_unique<FallbackMultigridSolver>(multigrid_options(c), f);
}

/// petsc's own option: PETSc's options over the defaults (PetscSolverOptions::options).
const OptionSpec& petsc_options_option() {
  static const OptionSpec o = [] {
    OptionSpec p = solver_param(
        option("petsc_options", OptionType::string, PetscSolverOptions{}.options, "--petsc-options",
               "petsc: PETSc options over the defaults, e.g. \"-pc_type hypre -pc_hypre_type "
               "boomeramg\" (docs/petsc.md)"));
    p.refused_elsewhere = true;
    return p;
  }();
  return o;
}

std::unique_ptr<LinearSolver> make_petsc(const SolverConfig& c) {
  PetscSolverOptions o;
  o.options = param_value(c, petsc_options_option()).get<std::string>();
  o.relative_tolerance = c.tolerance;
  o.max_iterations = c.max_iterations;
  return std::make_unique<PetscSolver>(o);  // checks the options: invalid_argument naming one
}

std::unique_ptr<LinearSolver> make_pcg(const SolverConfig& c) {
  PcgOptions o;
  o.relative_tolerance = c.tolerance;
  o.max_iterations = c.max_iterations;
  return preconditioner_row(preconditioner_name(c)).make(c, o);
}

void check(const SolverRow& row) {
  if (!row.make) throw std::logic_error("solver \"" + row.name + "\" registered without a factory");
  if (!row.memory)
    throw std::logic_error("solver \"" + row.name +
                           "\" registered without a memory model (config/memory_model.h)");
}

NamedTable<SolverRow> built_in() {
  NamedTable<SolverRow> t("solver", check);
  SolverRow cholmod{
      "cholmod", "CHOLMOD's supernodal Cholesky factorization",
      [](const SolverConfig& c) { return std::make_unique<CholmodSolver>(c.blas_threads); },
      [](const SolverConfig&, const SystemFigures& s) {
        return s.factor_bytes_per_unknown * s.dimension;
      }};
  cholmod.uses_blas_threads = true;
  SolverRow pcg{"pcg", "conjugate gradients with solver.preconditioner", make_pcg,
                [](const SolverConfig& c, const SystemFigures& s) {
                  return preconditioner_row(preconditioner_name(c)).memory(s);
                }};
  pcg.iterative = pcg.uses_preconditioner = true;
  SolverRow multigrid{"multigrid", "the basis's geometric multigrid, solver.cycles cycles",
                      make_multigrid, [](const SolverConfig&, const SystemFigures& s) {
                        return s.hierarchy_bytes_per_unknown * s.dimension;
                      }};
  multigrid.options = stall_guard_options();
  multigrid.iterative = multigrid.needs_hierarchy = multigrid.distributed = true;
  multigrid.default_tolerance = 0;  // run `cycles` cycles
  SolverRow petsc{"petsc", "PETSc's KSP, default CG + GAMG (docs/petsc.md)", make_petsc,
                  [](const SolverConfig&, const SystemFigures& s) {
                    return (kPetscMatrixCopies * kPetscBytesPerNonzero * s.nonzeros_per_row +
                            kPetscVectorBytesPerUnknown) *
                           s.dimension;
                  }};
  petsc.options = {petsc_options_option()};
  petsc.iterative = petsc.distributed = true;
  petsc.default_max_iterations = 3000;  // the paper's baseline: CG + AMG stopped at 3000
  SolverRow dense{"dense", "LLT of the dense matrix: a reference for small meshes",
                  [](const SolverConfig&) { return std::make_unique<DenseLltSolver>(); },
                  [](const SolverConfig&, const SystemFigures& s) {
                    return kDensePerUnknown2 * s.dimension * s.dimension;
                  }};
  for (SolverRow* row : {&cholmod, &pcg, &multigrid, &petsc, &dense}) t.add(std::move(*row));
  return t;
}

std::vector<OptionSpec> shared_options() {
  OptionSpec name = bind(
      option("solver.name", OptionType::string, "cholmod", "--solver", "Linear solver"),
      [](auto& c) -> auto& { return c.solver.name; });
  name.choices = [] { return solver_table().choices(); };
  // The solver's own default iteration cap, unless the config sets one.
  name.after = [](FlowConfig& c, const ConfigReader&, const std::string&) {
    c.solver.max_iterations = solver_row(c.solver.name).default_max_iterations;
  };
  OptionSpec tolerance = ranged(bind(
                                    option("solver.tolerance", OptionType::number, -1,
                                           "--tolerance", "Relative residual to stop at"),
                                    [](auto& c) -> auto& { return c.solver.tolerance; }),
                                0, 1);
  tolerance.default_text = "the solver's (1e-10; multigrid 0 = run --cycles)";
  OptionSpec max_iterations =
      ranged(bind(
                 option("solver.max_iterations", OptionType::integer, 1000, "--max-iterations",
                        "PCG, PETSc and the multigrid fallback's iteration cap"),
                 [](auto& c) -> auto& { return c.solver.max_iterations; }),
             1, 100000000);
  max_iterations.default_text = "the solver's (1000; petsc 3000)";
  OptionSpec preconditioner =
      solver_param(option("solver.preconditioner", OptionType::string, "jacobi", "--preconditioner",
                          "PCG preconditioner"));
  preconditioner.choices = [] { return preconditioner_table().choices(); };
  preconditioner.refused_elsewhere = true;
  preconditioner.owner_text = "solver \"pcg\"";
  preconditioner.selected = [](const FlowConfig& c) {
    return solver_row(c.solver.name).uses_preconditioner;
  };
  // The multigrid's cycle options, refused where no multigrid runs (as the solver or as CG's
  // preconditioner); when they are recorded is their declaration's (config/multigrid_params.cpp).
  std::vector<OptionSpec> options = {name, tolerance, max_iterations, preconditioner};
  for (OptionSpec o : multigrid_cycle_options()) {
    o.refused_elsewhere = true;
    if (split_key(o.key).second == "cycles") {
      // CG preconditioned by the multigrid applies one cycle an iteration, whatever this says.
      o.owner_text = "solver \"multigrid\" (CG's multigrid preconditioner is one cycle)";
      o.selected = [](const FlowConfig& c) { return solver_row(c.solver.name).needs_hierarchy; };
    } else {
      o.owner_text =
          "a multigrid (solver \"multigrid\", or \"pcg\" with preconditioner \"multigrid\")";
      o.selected = [](const FlowConfig& c) { return needs_hierarchy(c.solver); };
    }
    options.push_back(std::move(o));
  }
  return options;
}

NamedTable<SolverRow>& table() {
  static NamedTable<SolverRow> t = built_in();
  return t;
}

}  // namespace

const NamedTable<SolverRow>& solver_table() {
  return table();
}

void register_solver(SolverRow row) {
  table().add(std::move(row));
}

const SolverRow& solver_row(const std::string& name) {
  return table().at(name);
}

const std::vector<OptionSpec>& solver_options() {
  static const std::vector<OptionSpec> options = shared_options();
  return options;
}

const OptionSpec& solver_option(const std::string& leaf) {
  if (const OptionSpec* o = find_option(solver_options(), leaf)) return *o;
  for (const SolverRow& row : solver_table().rows())
    if (const OptionSpec* o = find_option(row.options, leaf)) return *o;
  throw std::logic_error("no solver option \"" + leaf + "\"");
}

std::string preconditioner_name(const SolverConfig& config) {
  static const OptionSpec& option = solver_option("preconditioner");
  return param_value(config, option).get<std::string>();
}

bool needs_hierarchy(const SolverConfig& config) {
  const SolverRow& row = solver_row(config.name);
  return row.needs_hierarchy || (row.uses_preconditioner &&
                                 preconditioner_row(preconditioner_name(config)).needs_hierarchy);
}

bool runs_across_ranks(const SolverConfig& config) {
  const SolverRow& row = solver_row(config.name);
  return row.distributed || (row.uses_preconditioner && preconditioner_name(config) == "multigrid");
}

}  // namespace mcf
