#pragma once
// The one place where config names map to implementations (bases, solvers, integrators).

#include "bases/basis.h"
#include "bases/octree_basis.h"
#include "datasets/mesh.h"
#include "flows/flow_config.h"
#include "solvers/linear_solver.h"

#include <memory>

namespace mcf {

/// The octree basis's options for a config; `analytic` shapes get the tight cube under "auto".
OctreeOptions octree_options(const OctreeConfig& c, bool analytic);
std::unique_ptr<Basis> make_basis(const FlowConfig& config, const TriangleMesh& mesh,
                                  bool analytic);
std::unique_ptr<LinearSolver> make_solver(const SolverConfig& config);

}  // namespace mcf
