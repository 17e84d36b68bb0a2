#pragma once
// Preconditioned conjugate gradients on a block of right-hand sides (docs/design.md "Layers",
// solvers/): k independent CG recurrences that share one pass over A per iteration (the
// flows always solve x, y, z together, so the matrix is streamed once instead of three times).
//
// Determinism: every reduction is summed in fixed 4096-row chunks whose partial sums are
// combined serially in chunk order, and the SpMV computes each row with a fixed order, so the
// iterates are bitwise identical for any TBB thread count (result files compare across runs).

#include "solvers/linear_solver.h"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/OrderingMethods>

#include <functional>
#include <memory>
#include <string>

namespace mcf {

enum class PcgPreconditioner {
  none,
  jacobi,               ///< inverse diagonal
  incomplete_cholesky,  ///< Eigen IncompleteCholesky<double, Lower, AMDOrdering<int>> (diagonal
                        ///< shift)
  external  ///< the hook set with PcgSolver::set_preconditioner (e.g. a multigrid cycle)
};

const char* to_string(PcgPreconditioner p);

struct PcgOptions {
  double relative_tolerance = 1e-10;  ///< stop when max_c ||b_c - A x_c|| / ||b_c|| <= this
  int max_iterations = 1000;          ///< iteration cap; reaching it gives max_iterations
  /// Stop early (status max_iterations) once, after at least 3 iterations, the mean reduction per
  /// iteration so far predicts that the cap will not reach the tolerance: for a caller with a
  /// better way to finish (the multigrid guard's factorization), the rest would be wasted.
  bool give_up_off_course = false;
  PcgPreconditioner preconditioner = PcgPreconditioner::jacobi;
};

class PcgSolver final : public LinearSolver {
 public:
  /// z = M^{-1} r for an n x k block (z is resized by the caller to r's shape before the call).
  using Preconditioner = std::function<void(const Eigen::MatrixXd& r, Eigen::MatrixXd& z)>;

  explicit PcgSolver(PcgOptions options = {});
  ~PcgSolver() override;

  std::string name() const override;
  const PcgOptions& options() const { return options_; }
  void set_options(const PcgOptions& options);

  /// Installs the external preconditioner (used when options.preconditioner == external).
  /// It must apply a fixed symmetric positive-definite operator for CG to converge.
  void set_preconditioner(Preconditioner preconditioner);

  /// Copies A (values only when the pattern is unchanged) and builds the preconditioner.
  /// not_positive_definite for a non-positive diagonal with Jacobi or an IC breakdown.
  /// hierarchy.pattern_key, when it is the key of the previous call, vouches for A's pattern
  /// (linear_solver.h): then only the size and nonzero count are checked, not every index.
  SolveReport set_matrix(const SparseMatrix& A, HierarchyView hierarchy = {}) override;
  /// The same for a M + b K, written straight into the copy set_matrix keeps (no other copy).
  SolveReport set_matrix_sum(const MatrixSum& sum, HierarchyView hierarchy = {}) override;
  using LinearSolver::set_matrix_sum;

  /// Y = A X with the deterministic parallel row SpMV (exposed for tests and other solvers).
  void multiply(const ConstMatrixRef& X, Eigen::MatrixXd& Y) const;

  /// How many set_matrix calls compared the new pattern index by index with the kept one.
  int pattern_comparisons() const { return kept_.comparisons(); }

 protected:
  /// Block PCG from the warm start X (solve(): zero if a resizable X has another shape).
  /// residuals[i] = max relative residual over columns after iteration i+1; the last entry
  /// and relative_residual are the true residual recomputed at exit.
  SolveReport solve_in_place(const ConstMatrixRef& B, MatrixRef X) override;

 private:
  struct Recurrence;  ///< the state and steps of one block PCG solve (solve_in_place)

  SolveReport build_preconditioner();
  SolveReport matrix_in_place();  ///< A_ holds the new matrix: finite check, preconditioner, status
  bool keeps_pattern(const SparseRef& A,
                     std::uint64_t key);  ///< A on A_'s pattern? (key or comparison)
  void apply_preconditioner(const Eigen::MatrixXd& r, Eigen::MatrixXd& z) const;

  PcgOptions options_;
  Preconditioner external_;
  SparseMatrix A_;
  KeptPattern kept_;  // the key of A_'s pattern, the comparisons made
  bool have_matrix_ = false;
  SolveStatus matrix_status_ = SolveStatus::failed;
  std::string matrix_message_ = "set_matrix not called";
  Eigen::VectorXd inv_diag_;
  // A solve's residual, preconditioned residual, direction and A times the direction (n x k),
  // kept from solve to solve: on a large mesh, fresh pages cost more than an iteration.
  struct Blocks {
    Eigen::MatrixXd R, Z, P, Q;
  };
  Blocks blocks_;
  std::unique_ptr<Eigen::IncompleteCholesky<double, Eigen::Lower, Eigen::AMDOrdering<int>>> ic_;
};

}  // namespace mcf
