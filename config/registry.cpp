#include "config/registry.h"

#include "config/solver_registry.h"

namespace mcf {

std::unique_ptr<Basis> make_basis(const FlowConfig& config, const TriangleMesh& mesh,
                                  bool analytic) {
  return basis_row(config.basis).make(config, mesh, analytic, needs_hierarchy(config.solver));
}

std::unique_ptr<LinearSolver> make_solver(const SolverConfig& config) {
  return solver_row(config.name).make(config);
}

}  // namespace mcf
