#pragma once
// A flow config's basis and solver, made from their rows (config/basis_registry.h,
// config/solver_registry.h): what the flow and the tests call.

#include "bases/basis.h"
#include "config/basis_registry.h"
#include "config/flow_config.h"
#include "datasets/mesh.h"
#include "solvers/linear_solver.h"

#include <memory>

namespace mcf {

/// The basis of `config` on `mesh`, with the geometric hierarchy where its solver needs one.
std::unique_ptr<Basis> make_basis(const FlowConfig& config, const TriangleMesh& mesh,
                                  bool analytic);
/// Throws std::invalid_argument for an unknown name or options the solver refuses.
std::unique_ptr<LinearSolver> make_solver(const SolverConfig& config);

}  // namespace mcf
