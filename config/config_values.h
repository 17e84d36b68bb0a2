#pragma once
// The options of one flow run as plain values: FlowConfig and the parts it is made of. The same
// JSON object is a cell of the experiment matrix and the "config" of result.json (with all defaults
// filled in), so the names below are stable. Reading, writing and checking them is
// config/flow_config.h's; the registries and the option specs include only this header, so that
// the reader may include them without a circle.

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace mcf {

struct OctreeConfig {
  std::string tracking = "tracked";  ///< tracked | rebuilt
  int depth = 8;                     ///< finest level, 4..10
  int cubature = 3;                  ///< 1 | 3 | 6 (rule's name, docs/design.md)
  std::string cube = "auto";         ///< auto | unit | tight
  bool refine_input = false;         ///< 1-to-4 split of the initial mesh first (Fig. 6, blue)
  /// normal-gradient (default): each step solves for the increment of the coefficients with the
  /// band's normal-gradient term added, so that multigrid converges (docs/octree-multigrid.md,
  /// "Stabilization") | none: the paper's system.
  std::string stabilization = "normal-gradient";
  /// c: the term's diagonal is c times the system's (ρ = c tr(a M + b K) / tr(S)); -1 = the
  /// solver's (0.5, which the multigrid cycles need; a direct solver's 1e-6, which only makes the
  /// system definite), filled in when the config is read (resolve_stabilization_weight).
  double stabilization_weight = -1;
};

struct SolverConfig {
  std::string name = "cholmod";  ///< cholmod | pcg | multigrid | petsc | dense (LLT reference)
  double tolerance =
      -1;  ///< relative residual; -1 = solver default (pcg 1e-10, multigrid 0 = run `cycles`)
  int max_iterations = 1000;              ///< PCG iteration cap (petsc: 3000, the paper's)
  std::string preconditioner = "jacobi";  ///< PCG: none | jacobi | ichol | multigrid
  std::string cycle = "W";                ///< multigrid: V | W
  int cycles = 1;                         ///< multigrid cycles per solve
  int smooth = 5;                         ///< Gauss–Seidel sweeps before and after (each)
  /// multigrid: k cycles promise to reduce the step's initial residual by stall_ratio^k; where they
  /// reduce it by less per cycle, CG preconditioned by the cycle takes over until they have
  /// (never below `fallback_tolerance`; solvers/multigrid_fallback.h). 0 = never.
  double stall_ratio = 0.2;
  /// multigrid: a step is converged only at or below this relative residual; one whose cycles end
  /// above it continues (more cycles, CG by the cycle, the factorization) until it is
  /// (solvers/multigrid_fallback.h: kDefaultResidualBound, which a test holds this to). 0 = no
  /// bound.
  double residual_bound = 1e-4;
  /// multigrid: hold smooth steps (the start fit the integrator's prediction, the cycles
  /// contracted) to residual_bound too; false = such a step keeps its fixed work above the bound
  /// and says so (solvers/multigrid_fallback.h, "Smooth steps").
  bool bound_smooth_steps = false;
  double fallback_tolerance = 1e-10;
  /// multigrid: the fallback CG's iterations after which (or on whose breakdown) CHOLMOD solves
  /// the step, and every later stalled step at once (solvers/multigrid_fallback.h). 0 = never.
  int direct_after = 10;
  /// multigrid (also as PCG's preconditioner): refresh the coarse operators term by term,
  /// recomputing only the terms whose values changed (MultigridOptions::galerkin_by_term).
  bool galerkin_by_term = false;
  /// multigrid: double | mixed (the finest sweeps in single precision inside a double-precision
  /// residual correction; MultigridOptions::mixed_precision).
  std::string precision = "double";
  /// multigrid: recompute the coarse operators on every k-th set_matrix of a pattern only
  /// (MultigridOptions::galerkin_refresh); 1 = every step.
  int galerkin_refresh = 1;
  /// petsc: PETSc options ("-pc_type hypre -pc_hypre_type boomeramg") over the defaults (CG +
  /// GAMG, solvers/petsc_solver.h), kept verbatim in result.json.
  std::string petsc_options;
  /// cholmod: OpenBLAS threads while it factorizes and solves, 0 = auto (auto_blas_threads,
  /// solvers/blas_threads.h), else this many, at most the flow's `threads`. Config key
  /// "blas_threads" (top level, as before it belonged to the solver).
  int blas_threads = 0;
  /// The values of solver rows' own options that have no field above (solver_param,
  /// config/option_spec.h: a solver added outside config/, as examples/damped_jacobi.cpp), by key
  /// ("omega"); the config reader fills every registered row's, each with its one default.
  nlohmann::json params = nlohmann::json::object();
};

struct FlowConfig {
  std::string mesh;                 ///< mesh spec (datasets/mesh_spec.h)
  std::string flow = "mcf";         ///< mcf | cmcf | heat
  std::string basis = "hat";        ///< hat | octree
  std::string mass = "consistent";  ///< hat basis: consistent | lumped
  OctreeConfig octree;
  SolverConfig solver;
  std::string integrator = "semi-implicit";  ///< see integrator_names()
  bool extrapolate = true;  ///< CN/BDF2: operators at the extrapolated X* (else frozen at X_n)
  double dt = 1e-3;
  int steps = 10;
  bool normalize_area = false;  ///< unit area, centroid at origin, before and after every step
  int threads = 0;              ///< 0 = all cores
  /// MPI ranks the solve runs on (a solver whose row is `distributed`: petsc). `mcfbench run`
  /// starts such a cell under `mpirun -n mpi_ranks`; `mcfbench flow` must be started so.
  int mpi_ranks = 1;
  int save_every = 0;  ///< write frame_NNNN.ply every K steps (0 = never)
  /// Collapse the mesh's zero-area faces before the flow (datasets/repair.h) instead of refusing
  /// them where the basis needs their cotangents (hat); the octree basis takes them as they are.
  bool repair_degenerate = false;
};

}  // namespace mcf
