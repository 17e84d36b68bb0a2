#pragma once
// An example of a solver written outside the harness's core (docs/extending.md "Adding a
// solver"): damped Jacobi iteration, x <- x + ω D⁻¹ (b - A x), ω = 2/3, registered as
// `solver.name` "damped-jacobi" by one row in damped_jacobi.cpp. It reads the shared options
// solver.tolerance (relative residual) and solver.max_iterations.
//
// It converges for the flows' systems a M + b K with a small step (M dominates, and the
// eigenvalues of D⁻¹ M lie in (0, 2) for P1 mass matrices), slowly as the step grows: an example
// of the interface, not a solver to use.

#include "solvers/linear_solver.h"

namespace mcf::examples {

class DampedJacobiSolver final : public LinearSolver {
 public:
  /// omega: the damping in x <- x + omega D^-1 (b - A x); check_every: sweeps between two
  /// residual norms (the stopping test), each a pass over the residual's three columns.
  DampedJacobiSolver(double tolerance, int max_iterations, double omega = 2.0 / 3.0,
                     int check_every = 1)
      : tolerance_(tolerance),
        max_iterations_(max_iterations),
        omega_(omega),
        check_every_(check_every) {}
  std::string name() const override { return "damped-jacobi"; }
  SolveReport set_matrix(const SparseMatrix& A, HierarchyView hierarchy = {}) override;

 protected:
  SolveReport solve_in_place(const ConstMatrixRef& B, MatrixRef X) override;

 private:
  double tolerance_;
  int max_iterations_;
  double omega_;
  int check_every_;
  SparseMatrix A_;
  Eigen::VectorXd inverse_diagonal_;
};

}  // namespace mcf::examples
