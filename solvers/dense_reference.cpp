#include "solvers/dense_reference.h"

#include <algorithm>
#include <cmath>

namespace mcf {

SolveReport DenseLltSolver::set_matrix(const SparseMatrix& A, HierarchyView /*hierarchy*/) {
  SolveReport rep;
  status_ = SolveStatus::converged;
  message_.clear();
  if (A.rows() != A.cols()) {
    status_ = SolveStatus::failed;
    message_ = "matrix is not square";
  } else if (A.rows() > max_dimension_) {
    status_ = SolveStatus::failed;
    message_ = "dimension " + std::to_string(A.rows()) + " too large for the dense reference";
  } else {
    A_ = Eigen::MatrixXd(A);
    if (!A_.allFinite()) {
      status_ = SolveStatus::numerical_issue;
      message_ = "matrix has NaN/inf";
    } else {
      llt_.compute(A_);
      if (llt_.info() != Eigen::Success) {
        status_ = SolveStatus::not_positive_definite;
        message_ = "dense LLT failed: matrix not positive definite";
      }
    }
  }
  rep.status = status_;
  rep.message = message_;
  return rep;
}

SolveReport DenseLltSolver::solve_in_place(const ConstMatrixRef& B, MatrixRef X) {
  SolveReport rep;
  if (status_ != SolveStatus::converged) {
    rep.status = status_;
    rep.message = message_;
    return rep;
  }
  if (B.rows() != A_.rows()) {
    rep.status = SolveStatus::failed;
    rep.message = "right-hand side has wrong size";
    return rep;
  }
  X = llt_.solve(B);
  rep.iterations = 1;
  report_true_residual(B, B - A_ * X, rep);
  return rep;
}

SolveReport dense_llt_solve(const SparseMatrix& A, const Eigen::MatrixXd& B, Eigen::MatrixXd& X,
                            Eigen::Index max_dimension) {
  DenseLltSolver s(max_dimension);
  SolveReport rep = s.set_matrix(A);
  if (!rep.ok()) return rep;
  return s.solve(B, X);
}

}  // namespace mcf
