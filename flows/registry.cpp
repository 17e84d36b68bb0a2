#include "flows/registry.h"

#include "bases/hat_basis.h"
#include "bases/octree_basis.h"
#include "bases/tracked_octree_basis.h"
#include "datasets/subdivide.h"
#include "solvers/cholmod_solver.h"
#include "solvers/dense_reference.h"
#include "solvers/multigrid.h"
#include "solvers/multigrid_fallback.h"
#include "solvers/multigrid_pcg.h"
#include "solvers/pcg_solver.h"
#include "solvers/petsc_solver.h"

#include <stdexcept>

namespace mcf {
OctreeOptions octree_options(const OctreeConfig& c, bool analytic) {
  OctreeOptions o;
  o.depth = c.depth;
  o.cubature = c.cubature;
  o.refine_input = c.refine_input;
  o.normal_gradient = c.stabilization == "normal-gradient";
  // "auto": the unit cube for models normalised into it (the paper's setting), the tight cube
  // around analytic shapes (which keep their own size).
  if (c.cube == "unit")
    o.cube = OctreeCube::unit;
  else if (c.cube == "tight")
    o.cube = OctreeCube::tight;
  else
    o.cube = analytic ? OctreeCube::tight : OctreeCube::automatic;
  return o;
}

namespace {

MultigridOptions multigrid_options(const SolverConfig& c) {
  MultigridOptions o;
  o.cycle = c.cycle == "V" ? MultigridCycle::V : MultigridCycle::W;
  o.cycles = c.cycles;
  o.pre_smooth = o.post_smooth = c.smooth;
  o.tolerance = c.tolerance;
  o.galerkin_by_term = c.galerkin_by_term;
  o.mixed_precision = c.precision == "mixed";
  return o;
}

}  // namespace

std::unique_ptr<Basis> make_basis(const FlowConfig& config, const TriangleMesh& mesh,
                                  bool analytic) {
  if (config.basis == "hat") {
    // The surface hierarchy only where a multigrid uses it: it costs set-up time and memory.
    const SolverConfig& s = config.solver;
    std::optional<SurfaceHierarchyOptions> hierarchy;
    if (s.name == "multigrid" || (s.name == "pcg" && s.preconditioner == "multigrid"))
      hierarchy = SurfaceHierarchyOptions{};
    const MassKind mass = config.mass == "lumped" ? MassKind::lumped : MassKind::consistent;
    if (config.octree.refine_input)  // the 1-to-4 split flows; the input's vertices are output
      return std::make_unique<HatBasis>(subdivide_midpoint(mesh), mass, hierarchy,
                                        mesh.num_vertices());
    return std::make_unique<HatBasis>(mesh, mass, hierarchy);
  }
  if (config.basis == "octree") {
    const OctreeOptions o = octree_options(config.octree, analytic);
    if (config.octree.tracking == "rebuilt") return std::make_unique<RebuiltOctreeBasis>(mesh, o);
    return std::make_unique<TrackedOctreeBasis>(mesh, o);
  }
  throw std::invalid_argument("unknown basis \"" + config.basis + "\"");
}

std::unique_ptr<LinearSolver> make_solver(const SolverConfig& config) {
  if (config.name == "cholmod") return std::make_unique<CholmodSolver>();
  if (config.name == "dense") return std::make_unique<DenseLltSolver>();
  if (config.name == "multigrid") {
    if (config.stall_ratio <= 0)
      return std::make_unique<MultigridSolver>(multigrid_options(config));
    StallFallbackOptions f;
    f.stall_ratio = config.stall_ratio;
    f.tolerance = config.fallback_tolerance;
    f.max_iterations = config.max_iterations;
    return std::make_unique<FallbackMultigridSolver>(multigrid_options(config), f);
  }
  if (config.name == "petsc") {
    PetscSolverOptions o;
    o.options = config.petsc_options;
    o.relative_tolerance = config.tolerance;
    o.max_iterations = config.max_iterations;
    return std::make_unique<PetscSolver>(o);  // checks the options: invalid_argument naming one
  }
  if (config.name == "pcg") {
    PcgOptions o;
    o.relative_tolerance = config.tolerance;
    o.max_iterations = config.max_iterations;
    if (config.preconditioner == "multigrid") {
      MultigridOptions cycle = multigrid_options(config);
      cycle.cycles = 1;
      cycle.tolerance = 0;
      return std::make_unique<MultigridPcgSolver>(cycle, o);
    }
    if (config.preconditioner == "none")
      o.preconditioner = PcgPreconditioner::none;
    else if (config.preconditioner == "jacobi")
      o.preconditioner = PcgPreconditioner::jacobi;
    else
      o.preconditioner = PcgPreconditioner::incomplete_cholesky;
    return std::make_unique<PcgSolver>(o);
  }
  throw std::invalid_argument("unknown solver \"" + config.name + "\"");
}

}  // namespace mcf
