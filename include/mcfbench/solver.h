#pragma once
// Linear solvers by name, as a flow uses them, and solvers defined by the caller, which then run
// in flows and experiments like the built-in ones (docs/library.md#a-solver-of-your-own).

#include "mcfbench/export.h"
#include "mcfbench/types.h"

#include <functional>
#include <memory>
#include <string>

namespace mcfbench {

/// How a set_matrix or solve went (result.json's per-step "solver").
struct SolveInfo {
  /// converged | max_iterations (both let a flow go on) | not_positive_definite |
  /// numerical_issue | failed
  std::string status;
  bool ok = false;  ///< converged or max_iterations
  int iterations = 0;
  double relative_residual = 0;  ///< max over the columns of ||b - A x|| / ||b||
  std::string message;
};

class MCFBENCH_API Solver {
 public:
  /// The solver a flow with these options runs: "solver" (its name; default cholmod) and the
  /// solver keys ("tolerance", "max-iterations", "preconditioner", "cycle", "cycles", ...).
  /// Throws InputError naming a bad option. A multigrid needs a basis's hierarchy, which a solver
  /// made here does not have: use it through flow().
  explicit Solver(const Options& options = {});
  ~Solver();
  Solver(Solver&&) noexcept;
  Solver& operator=(Solver&&) noexcept;

  /// The name as result.json's "solver_name" has it ("multigrid-W").
  std::string name() const;
  /// Sets the symmetric positive-definite matrix A (n x n, both triangles stored); a
  /// factorization that meets a non-positive pivot says not_positive_definite.
  SolveInfo set_matrix(const SparseMatrix& A);
  /// Solves A X = B for every column of B (n x k). X: the start on entry (iterative solvers use
  /// it; resized to n x k, zero, if it has another shape), the solution on exit.
  SolveInfo solve(const DenseMatrix& B, DenseMatrix& X);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Solves A X = B for the matrix its factory was given: B is n x 3 (one column per coordinate),
/// X holds the start on entry (the flow's prediction; meaningful for an iterative definition)
/// and must hold the solution on exit, n x 3.
using SolveFunction = std::function<void(const DenseMatrix& B, DenseMatrix& X)>;
/// Called with the system matrix each time the flow sets a new one (values or pattern differ
/// from the last: every step of MCF and cMCF, once for heat flow); returns the solve for it.
using SolverFactory = std::function<SolveFunction(const SparseMatrix& A)>;

struct SolverDefinition {
  std::string name;  ///< the value of the "solver" option that selects it
  std::string help;  ///< one line, for listings
  SolverFactory factory;
  /// The solve reads the start X (the flow then keeps the previous step's solution to predict
  /// it), and its memory is counted as a copy of A and a few vectors; otherwise as a sparse
  /// Cholesky factor's.
  bool iterative = false;
};

/// Adds a solver to the solver option's values, for every flow and experiment of this process.
/// Each solve is recorded as a built-in solver's: its time in the step's "solve" seconds, its
/// true relative residual (computed by the library), status converged (numerical_issue where X
/// is not finite). An exception the factory or the solve throws ends the flow and reaches the
/// caller of flow() unchanged (a cell of run() records it as the cell's error). Defining a name
/// again replaces the definition; a built-in solver's name is an InputError.
MCFBENCH_API void register_solver(SolverDefinition definition);

}  // namespace mcfbench
