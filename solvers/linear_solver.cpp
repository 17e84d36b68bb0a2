#include "solvers/linear_solver.h"

#include "core/parallel.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>

namespace mcf {

const char* to_string(SolveStatus s) {
  switch (s) {
    case SolveStatus::converged:
      return "converged";
    case SolveStatus::max_iterations:
      return "max_iterations";
    case SolveStatus::not_positive_definite:
      return "not_positive_definite";
    case SolveStatus::numerical_issue:
      return "numerical_issue";
    case SolveStatus::failed:
      return "failed";
  }
  return "unknown";
}

std::uint64_t new_pattern_key() {
  static std::atomic<std::uint64_t> next{1};
  return next.fetch_add(1, std::memory_order_relaxed);
}

bool same_pattern(const SparseRef& A, const SparseRef& B) {
  // Views of one pattern (a basis's mass and stiffness) share its arrays: nothing to compare.
  const bool shared =
      A.outerIndexPtr() == B.outerIndexPtr() && A.innerIndexPtr() == B.innerIndexPtr();
  return A.isCompressed() && B.isCompressed() && A.rows() == B.rows() && A.cols() == B.cols() &&
         A.nonZeros() == B.nonZeros() &&
         (shared ||
          (std::equal(A.outerIndexPtr(), A.outerIndexPtr() + A.outerSize() + 1,
                      B.outerIndexPtr()) &&
           std::equal(A.innerIndexPtr(), A.innerIndexPtr() + A.nonZeros(), B.innerIndexPtr())));
}

void sum_on_pattern(const MatrixSum& sum, SparseMatrix& A) {
  const double *m = sum.M.valuePtr(), *k = sum.K.valuePtr();
  const double* q = sum.S ? sum.S->valuePtr() : nullptr;
  const double a = sum.a, b = sum.b, s = sum.s;
  double* out = A.valuePtr();
  if (q)
    parallel_for_indices<Eigen::Index>(sum.M.nonZeros(), 1 << 14, [&](Eigen::Index i) {
      out[i] = sum_entry(a, m[i], b, k[i], s, q[i]);
    });
  else
    parallel_for_indices<Eigen::Index>(
        sum.M.nonZeros(), 1 << 14, [&](Eigen::Index i) { out[i] = sum_entry(a, m[i], b, k[i]); });
}

SparseMatrix general_sum(const MatrixSum& sum) {
  SparseMatrix A =
      sum.b == 0.0 ? SparseMatrix(sum.a * sum.M) : SparseMatrix(sum.a * sum.M + sum.b * sum.K);
  if (sum.S && sum.s != 0.0) A = SparseMatrix(A + sum.s * *sum.S);
  A.makeCompressed();
  return A;
}

bool summable(const SparseRef& M, const SparseRef& K) {
  return M.isCompressed() && K.isCompressed() && M.rows() == K.rows() && M.cols() == K.cols() &&
         M.nonZeros() == K.nonZeros();
}

bool summable(const MatrixSum& sum) {
  return summable(sum.M, sum.K) && (!sum.S || summable(sum.M, *sum.S));
}

SolveReport LinearSolver::set_matrix_sum(const MatrixSum& sum, HierarchyView hierarchy) {
  if (!summable(sum)) {
    // Off one pattern: Eigen merges the patterns; no key, as the union is not what it vouched for.
    sum_ = general_sum(sum);
    sum_key_ = 0;
    return set_matrix(sum_, HierarchyView{hierarchy.prolongations, hierarchy.colours, 0});
  }
  // The key vouches for M's pattern as it does for A's (HierarchyView); without one, compare.
  const SparseRef& M = sum.M;
  const std::uint64_t key = hierarchy.pattern_key;
  if (key == 0 || key != sum_key_ || sum_.nonZeros() != M.nonZeros() || sum_.rows() != M.rows()) {
    if (!same_pattern(sum_, M)) sum_ = M;
  }
  sum_key_ = key;
  sum_on_pattern(sum, sum_);
  return set_matrix(sum_, hierarchy);
}

void report_true_residual(const ConstMatrixRef& B, const ConstMatrixRef& R, SolveReport& report) {
  double worst = 0.0;
  for (Eigen::Index c = 0; c < B.cols(); ++c) {
    const double bn = B.col(c).norm();
    const double rn = R.col(c).norm();
    const double rel = bn > 0.0 ? rn / bn : rn;
    if (!std::isfinite(rel))
      worst = rel;
    else if (std::isfinite(worst))
      worst = std::max(worst, rel);
  }
  report.relative_residual = worst;
  report.residuals = {worst};
  if (!std::isfinite(worst)) {
    report.status = SolveStatus::numerical_issue;
    report.message = "solution has NaN/inf";
  }
}

SolveReport LinearSolver::solve(const ConstMatrixRef& B, MatrixRef X) {
  if (X.rows() != B.rows() || X.cols() != B.cols()) {
    SolveReport report;
    report.status = SolveStatus::failed;
    report.message = "warm start has " + std::to_string(X.rows()) + " x " +
                     std::to_string(X.cols()) + " entries, the right-hand side " +
                     std::to_string(B.rows()) + " x " + std::to_string(B.cols());
    start_fit_ = -1;
    return report;
  }
  SolveReport report = solve_in_place(B, X);
  start_fit_ = -1;  // a hint for one solve
  return report;
}

SolveReport LinearSolver::solve(const ConstMatrixRef& B, Eigen::MatrixXd& X) {
  if (X.rows() != B.rows() || X.cols() != B.cols()) X.setZero(B.rows(), B.cols());
  SolveReport report = solve_in_place(B, MatrixRef(X));
  start_fit_ = -1;
  return report;
}

}  // namespace mcf
