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
  int max_iterations = 1000;  ///< PCG iteration cap (petsc: 3000, the paper's)
  /// cholmod: OpenBLAS threads while it factorizes and solves, 0 = auto (auto_blas_threads,
  /// solvers/blas_threads.h), else this many, at most the flow's `threads`. Config key
  /// "blas_threads" (top level, as before it belonged to the solver).
  int blas_threads = 0;
  /// The values of the solvers' own options, by key within "solver" (CG's "preconditioner", the
  /// multigrid's "cycles", PETSc's "petsc_options", a solver added outside config/'s "omega"): each
  /// component declares its options with solver_param (config/option_spec.h) and its default once,
  /// and reads them back with param_value (the multigrid's: config/multigrid_params.h). The config
  /// reader fills every registered row's; a key left out of a config built in code means its
  /// default.
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
