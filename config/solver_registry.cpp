#include "config/solver_registry.h"

#include "config/config_reader.h"
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
  if (c.stall_ratio <= 0 && c.residual_bound <= 0)
    return std::make_unique<MultigridSolver>(multigrid_options(c));
  StallFallbackOptions f;
  f.stall_ratio = c.stall_ratio;
  f.residual_bound = c.residual_bound;
  f.bound_smooth_steps = c.bound_smooth_steps;
  f.tolerance = c.fallback_tolerance;
  f.max_iterations = c.max_iterations;
  f.direct_after = c.direct_after;
  f.direct_blas_threads = c.blas_threads;
  return std::make_unique<FallbackMultigridSolver>(multigrid_options(c), f);
}

std::unique_ptr<LinearSolver> make_petsc(const SolverConfig& c) {
  PetscSolverOptions o;
  o.options = c.petsc_options;
  o.relative_tolerance = c.tolerance;
  o.max_iterations = c.max_iterations;
  return std::make_unique<PetscSolver>(o);  // checks the options: invalid_argument naming one
}

std::unique_ptr<LinearSolver> make_pcg(const SolverConfig& c) {
  PcgOptions o;
  o.relative_tolerance = c.tolerance;
  o.max_iterations = c.max_iterations;
  return preconditioner_row(c.preconditioner).make(c, o);
}

void check(const SolverRow& row) {
  if (!row.make) throw std::logic_error("solver \"" + row.name + "\" registered without a factory");
  if (!row.memory)
    throw std::logic_error("solver \"" + row.name +
                           "\" registered without a memory model (config/memory_model.h)");
}

OptionSpec bound_smooth_steps_option() {
  OptionSpec o = bind(
      option("bound_smooth_steps", OptionType::boolean, false, "--bound-smooth-steps",
             "Multigrid: hold smooth steps to the residual bound too; by default "
             "a step whose start fit the integrator's prediction (theta >= 0.5) "
             "and whose cycles contracted keeps its fixed work above the bound "
             "and says so"),
      [](auto& c) -> auto& { return c.solver.bound_smooth_steps; });
  o.flag_kind = FlagKind::set_true;
  return o;
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
  cholmod.default_stabilization_weight = kDefiniteStabilizationWeight;
  SolverRow pcg{"pcg", "conjugate gradients with solver.preconditioner", make_pcg,
                [](const SolverConfig& c, const SystemFigures& s) {
                  return preconditioner_row(c.preconditioner).memory(s);
                }};
  pcg.iterative = pcg.uses_preconditioner = true;
  SolverRow multigrid{"multigrid", "the basis's geometric multigrid, solver.cycles cycles",
                      make_multigrid, [](const SolverConfig&, const SystemFigures& s) {
                        return s.hierarchy_bytes_per_unknown * s.dimension;
                      }};
  multigrid.options = {
      ranged(bind(
                 option("stall_ratio", OptionType::number, 0.2, "--stall-ratio",
                        "Multigrid: where the cycles reduce the residual by less than this per "
                        "cycle, CG preconditioned by the cycle takes over until they have reached "
                        "what this ratio promises (or the residual bound); 0 = never"),
                 [](auto& c) -> auto& { return c.solver.stall_ratio; }),
             0, 1),
      ranged(bind(
                 option("residual_bound", OptionType::number, kDefaultResidualBound,
                        "--residual-bound",
                        "Multigrid: a step is converged only at or below this relative residual; "
                        "one whose cycles end above it continues with more cycles, then CG "
                        "preconditioned by the cycle, then the factorization; 0 = no bound"),
                 [](auto& c) -> auto& { return c.solver.residual_bound; }),
             0, 1),
      bound_smooth_steps_option(),
      ranged(bind(
                 option("fallback_tolerance", OptionType::number, 1e-10, "--fallback-tolerance",
                        "Multigrid: the fallback CG never stops below this relative residual"),
                 [](auto& c) -> auto& { return c.solver.fallback_tolerance; }),
             1e-300, 1),
      ranged(bind(
                 option("direct_after", OptionType::integer, 10, "--direct-after",
                        "Multigrid: when the fallback CG has not reached its target after this "
                        "many iterations, or breaks down, a sparse Cholesky factorization solves "
                        "the step, and later steps that need more than their cycles at once; "
                        "0 = never"),
                 [](auto& c) -> auto& { return c.solver.direct_after; }),
             0, 1000000)};
  multigrid.iterative = multigrid.needs_hierarchy = multigrid.distributed = true;
  multigrid.default_tolerance = 0;  // run `cycles` cycles
  SolverRow petsc{"petsc", "PETSc's KSP, default CG + GAMG (docs/petsc.md)", make_petsc,
                  [](const SolverConfig&, const SystemFigures& s) {
                    return (kPetscMatrixCopies * kPetscBytesPerNonzero * s.nonzeros_per_row +
                            kPetscVectorBytesPerUnknown) *
                           s.dimension;
                  }};
  OptionSpec petsc_options = bind(
      option("petsc_options", OptionType::string, "", "--petsc-options",
             "petsc: PETSc options over the defaults, e.g. \"-pc_type hypre -pc_hypre_type "
             "boomeramg\" (docs/petsc.md)"),
      [](auto& c) -> auto& { return c.solver.petsc_options; });
  petsc_options.refused_elsewhere = true;
  petsc.options = {petsc_options};
  petsc.iterative = petsc.distributed = true;
  petsc.default_max_iterations = 3000;  // the paper's baseline: CG + AMG stopped at 3000
  SolverRow dense{"dense", "LLT of the dense matrix: a reference for small meshes",
                  [](const SolverConfig&) { return std::make_unique<DenseLltSolver>(); },
                  [](const SolverConfig&, const SystemFigures& s) {
                    return kDensePerUnknown2 * s.dimension * s.dimension;
                  }};
  dense.default_stabilization_weight = kDefiniteStabilizationWeight;
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
  OptionSpec preconditioner = bind(
      option("solver.preconditioner", OptionType::string, "jacobi", "--preconditioner",
             "PCG preconditioner"),
      [](auto& c) -> auto& { return c.solver.preconditioner; });
  preconditioner.choices = [] { return preconditioner_table().choices(); };
  preconditioner.refused_elsewhere = true;
  preconditioner.owner_text = "solver \"pcg\"";
  preconditioner.selected = [](const FlowConfig& c) {
    return solver_row(c.solver.name).uses_preconditioner;
  };
  // The multigrid's cycle wherever it runs (as the solver or as PCG's preconditioner); recorded
  // always (the cells of every earlier run record them), refused where no multigrid runs.
  const auto cycle_option = [](OptionSpec o) {
    o.refused_elsewhere = true;
    o.owner_text =
        "a multigrid (solver \"multigrid\", or \"pcg\" with preconditioner \"multigrid\")";
    o.selected = [](const FlowConfig& c) { return needs_hierarchy(c.solver); };
    return o;
  };
  OptionSpec cycle = bind(
      option("solver.cycle", OptionType::string, "W", "--cycle",
             "Multigrid cycle (solver and preconditioner)"),
      [](auto& c) -> auto& { return c.solver.cycle; });
  cycle.choices = [] { return std::vector<Choice>{{"V", ""}, {"W", ""}}; };
  cycle = cycle_option(cycle);
  OptionSpec cycles = ranged(
      bind(
          option("solver.cycles", OptionType::integer, 1, "--cycles", "Multigrid cycles per solve"),
          [](auto& c) -> auto& { return c.solver.cycles; }),
      1, 10000);
  // CG preconditioned by the multigrid applies one cycle an iteration, whatever this says.
  cycles.refused_elsewhere = true;
  cycles.owner_text = "solver \"multigrid\" (CG's multigrid preconditioner is one cycle)";
  cycles.selected = [](const FlowConfig& c) { return solver_row(c.solver.name).needs_hierarchy; };
  OptionSpec smooth =
      cycle_option(ranged(bind(
                              option("solver.smooth", OptionType::integer, 5, "--smooth",
                                     "Gauss-Seidel sweeps before and after each coarse correction"),
                              [](auto& c) -> auto& { return c.solver.smooth; }),
                          0, 1000));
  // The multigrid's options added later, recorded only when set (cells of earlier runs lack
  // them), refused where no multigrid runs as the cycle's are.
  const auto multigrid_option = [&](OptionSpec o) {
    o = cycle_option(std::move(o));
    o.recorded = Recorded::when_set;
    return o;
  };
  OptionSpec by_term = multigrid_option(bind(
      option("solver.galerkin_by_term", OptionType::boolean, false, "--galerkin-by-term",
             "Multigrid: refresh the coarse operators term by term, only the terms whose "
             "values changed (cMCF: the mass alone); equal to the sum's products up to "
             "rounding"),
      [](auto& c) -> auto& { return c.solver.galerkin_by_term; }));
  by_term.flag_kind = FlagKind::set_true;
  OptionSpec precision = multigrid_option(bind(
      option("solver.precision", OptionType::string, "double", "--precision",
             "Multigrid: the finest level's sweeps in double or in single precision inside "
             "a double-precision residual correction (same solution, fewer bytes a sweep)"),
      [](auto& c) -> auto& { return c.solver.precision; }));
  precision.choices = [] {
    return std::vector<Choice>{{"double", "every sweep in double precision"},
                               {"mixed", "the finest sweeps read a single-precision copy"}};
  };
  OptionSpec refresh = multigrid_option(
      ranged(bind(
                 option("solver.galerkin_refresh", OptionType::integer, 1, "--galerkin-refresh",
                        "Multigrid: recompute the coarse operators on every k-th step only (the "
                        "finest level, hence the solution, stays exact; the coarse corrections use "
                        "operators up to k - 1 steps old)"),
                 [](auto& c) -> auto& { return c.solver.galerkin_refresh; }),
             1, 1000));
  return {name,   tolerance, max_iterations, preconditioner, cycle,
          cycles, smooth,    by_term,        precision,      refresh};
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

bool needs_hierarchy(const SolverConfig& config) {
  const SolverRow& row = solver_row(config.name);
  return row.needs_hierarchy ||
         (row.uses_preconditioner && preconditioner_row(config.preconditioner).needs_hierarchy);
}

bool runs_across_ranks(const SolverConfig& config) {
  const SolverRow& row = solver_row(config.name);
  return row.distributed || (row.uses_preconditioner && config.preconditioner == "multigrid");
}

}  // namespace mcf
