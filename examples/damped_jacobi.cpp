#include "examples/damped_jacobi.h"

#include "config/option_spec.h"
#include "config/solver_registry.h"

namespace mcf::examples {

SolveReport DampedJacobiSolver::set_matrix(const SparseMatrix& A, HierarchyView) {
  A_ = A;
  inverse_diagonal_ = A.diagonal().cwiseInverse();
  SolveReport r;
  if (!inverse_diagonal_.allFinite() || (A.diagonal().array() <= 0).any())
    r.status = SolveStatus::not_positive_definite;
  return r;
}

SolveReport DampedJacobiSolver::solve_in_place(const ConstMatrixRef& B, MatrixRef X) {
  SolveReport r;
  const Eigen::ArrayXd b_norm = B.colwise().norm().transpose().array().max(1e-300);
  auto relative = [&](const Eigen::MatrixXd& R) {
    return (R.colwise().norm().transpose().array() / b_norm).maxCoeff();
  };
  Eigen::MatrixXd R = B - A_ * X;
  r.relative_residual = relative(R);
  while (r.relative_residual > tolerance_ && r.iterations < max_iterations_) {
    for (int k = 0; k < check_every_ && r.iterations < max_iterations_; ++k, ++r.iterations) {
      X += omega_ * (inverse_diagonal_.asDiagonal() * R);
      R = B - A_ * X;
    }
    r.relative_residual = relative(R);
    r.residuals.push_back(r.relative_residual);
  }
  if (!std::isfinite(r.relative_residual))
    r.status = SolveStatus::numerical_issue;
  else if (r.relative_residual > tolerance_)
    r.status = SolveStatus::max_iterations;
  return r;
}

namespace {

// The one row that makes the solver selectable: by `mcfbench flow --solver damped-jacobi`, by
// "solver.name" in a flow or experiment config, and in `run` and `expand`.
const bool registered = [] {
  SolverRow row;
  row.name = "damped-jacobi";
  row.help = "damped Jacobi iteration (examples/damped_jacobi.h)";
  row.make = [](const SolverConfig& c) -> std::unique_ptr<LinearSolver> {
    return std::make_unique<DampedJacobiSolver>(
        c.tolerance, c.max_iterations, param_value(c, solver_option("omega")).get<double>(),
        param_value(c, solver_option("check_every")).get<int>());
  };
  // Its own options, config keys solver.omega and solver.check_every (flags --omega and
  // --check-every), each with its one default; refused under any other solver.
  row.options = {solver_param(ranged(option("omega", OptionType::number, 2.0 / 3.0, "--omega",
                                            "damped-jacobi: the damping omega of each sweep"),
                                     1e-3, 1)),
                 solver_param(ranged(option("check_every", OptionType::integer, 1, "--check-every",
                                            "damped-jacobi: sweeps between two residual checks"),
                                     1, 1000))};
  // A copy of the system matrix and a few vectors per unknown.
  row.memory = [](const SolverConfig&, const SystemFigures& s) {
    return (12 * s.nonzeros_per_row + 6 * 8) * s.dimension;
  };
  row.iterative = true;
  register_solver(std::move(row));
  return true;
}();

}  // namespace
}  // namespace mcf::examples
