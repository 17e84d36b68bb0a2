#pragma once
// The one place where config names map to implementations (bases, solvers, integrators).

#include "bases/basis.h"
#include "datasets/mesh.h"
#include "flows/flow_config.h"
#include "solvers/linear_solver.h"

#include <memory>

namespace mcf {

std::unique_ptr<Basis> make_basis(const FlowConfig& config, const TriangleMesh& mesh,
                                  bool analytic);
std::unique_ptr<LinearSolver> make_solver(const SolverConfig& config);

}  // namespace mcf
