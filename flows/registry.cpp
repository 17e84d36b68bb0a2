#include "flows/registry.h"

#include "bases/hat_basis.h"
#include "solvers/cholmod_solver.h"
#include "solvers/dense_reference.h"
#include "solvers/pcg_solver.h"

#include <stdexcept>

namespace mcf {

std::unique_ptr<Basis> make_basis(const FlowConfig& config, const TriangleMesh& mesh, bool /*analytic*/) {
  if (config.basis == "hat")
    return std::make_unique<HatBasis>(mesh, config.mass == "lumped" ? MassKind::lumped : MassKind::consistent);
  throw std::invalid_argument("basis \"" + config.basis + "\" is not available in this build");
}

std::unique_ptr<LinearSolver> make_solver(const SolverConfig& config) {
  if (config.name == "cholmod") return std::make_unique<CholmodSolver>();
  if (config.name == "dense") return std::make_unique<DenseLltSolver>();
  if (config.name == "pcg") {
    PcgOptions o;
    o.relative_tolerance = config.tolerance;
    o.max_iterations = config.max_iterations;
    if (config.preconditioner == "none") o.preconditioner = PcgPreconditioner::none;
    else if (config.preconditioner == "jacobi") o.preconditioner = PcgPreconditioner::jacobi;
    else if (config.preconditioner == "ichol") o.preconditioner = PcgPreconditioner::incomplete_cholesky;
    else throw std::invalid_argument("solver.preconditioner \"" + config.preconditioner + "\" is not available");
    return std::make_unique<PcgSolver>(o);
  }
  throw std::invalid_argument("solver \"" + config.name + "\" is not available in this build");
}

}  // namespace mcf
