#pragma once
// Dense LL^T reference solve for small systems: an independent check on the sparse solvers
// (tests) and a trivially correct coarsest-level solver for tiny hierarchies.

#include "solvers/linear_solver.h"

#include <Eigen/Cholesky>

namespace mcf {

/// The largest system the dense reference factorizes (5000² doubles = 200 MB).
inline constexpr Eigen::Index kDenseMaxDimension = 5000;

/// Solves A X = B with Eigen's dense LLT. Refuses (status failed) above max_dimension so a
/// mistaken call on a real mesh does not allocate n^2 doubles. Reports iterations = 1 and the
/// true relative residual, like CholmodSolver.
SolveReport dense_llt_solve(const SparseMatrix& A, const Eigen::MatrixXd& B, Eigen::MatrixXd& X,
                            Eigen::Index max_dimension = kDenseMaxDimension);

/// The same as a LinearSolver (factorizes in set_matrix, ignores the warm start).
class DenseLltSolver final : public LinearSolver {
 public:
  explicit DenseLltSolver(Eigen::Index max_dimension = kDenseMaxDimension)
      : max_dimension_(max_dimension) {}
  std::string name() const override { return "dense-llt"; }
  Eigen::Index max_dimension() const override { return max_dimension_; }
  SolveReport set_matrix(const SparseMatrix& A, HierarchyView hierarchy = {}) override;

 protected:
  SolveReport solve_in_place(const ConstMatrixRef& B, MatrixRef X) override;

 private:
  Eigen::Index max_dimension_;
  Eigen::MatrixXd A_;
  Eigen::LLT<Eigen::MatrixXd> llt_;
  SolveStatus status_ = SolveStatus::failed;
  std::string message_ = "set_matrix not called";
};

}  // namespace mcf
