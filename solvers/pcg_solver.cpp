#include "solvers/pcg_solver.h"

#include "core/parallel.h"
#include "solvers/symmetric_multiply.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace mcf {
namespace {

using Eigen::Index;
using Eigen::MatrixXd;
using Eigen::VectorXd;

// Fixed chunk size for every parallel loop and every reduction: the partition of the rows
// does not depend on the thread count, so neither does any floating-point sum.
constexpr Index kChunk = 4096;

template <class F>
void for_chunks(Index n, F&& f) {
  parallel_for_chunks(n, kChunk, f);
}

// Eight independent accumulators in a fixed pattern: the lanes map onto SIMD registers without
// any reassociation (so no -ffast-math is needed and the order is a function of the chunk
// bounds only), and they break the add-latency chain of a single running sum.
double chunk_dot(const double* u, const double* v, Index b, Index e) {
  constexpr int L = 8;
  double s[L] = {};
  Index i = b;
  for (; i + L <= e; i += L)
    for (int j = 0; j < L; ++j) s[j] += u[i + j] * v[i + j];
  for (int j = 0; i < e; ++i, ++j) s[j] += u[i] * v[i];
  return ((s[0] + s[1]) + (s[2] + s[3])) + ((s[4] + s[5]) + (s[6] + s[7]));
}

// Combines per-chunk partials (chunk-major, k per chunk) serially in chunk order.
void combine(const std::vector<double>& partials, Index k, VectorXd& out) {
  out.setZero(k);
  const Index chunks = static_cast<Index>(partials.size()) / std::max<Index>(k, 1);
  for (Index ch = 0; ch < chunks; ++ch)
    for (Index c = 0; c < k; ++c) out[c] += partials[static_cast<std::size_t>(ch * k + c)];
}

/// out[c] = U.col(c) . V.col(c), deterministic for any thread count.
void column_dots(const ConstMatrixRef& U, const ConstMatrixRef& V, VectorXd& out) {
  const Index n = U.rows(), k = U.cols();
  const Index chunks = (n + kChunk - 1) / kChunk;
  std::vector<double> partials(static_cast<std::size_t>(chunks * k), 0.0);
  for_chunks(n, [&](Index ch, Index b, Index e) {
    for (Index c = 0; c < k; ++c)
      partials[static_cast<std::size_t>(ch * k + c)] =
          chunk_dot(U.col(c).data(), V.col(c).data(), b, e);
  });
  combine(partials, k, out);
}

bool all_finite(const VectorXd& v) {
  return v.allFinite();
}

}  // namespace

const char* to_string(PcgPreconditioner p) {
  switch (p) {
    case PcgPreconditioner::none:
      return "none";
    case PcgPreconditioner::jacobi:
      return "jacobi";
    case PcgPreconditioner::incomplete_cholesky:
      return "incomplete_cholesky";
    case PcgPreconditioner::external:
      return "external";
  }
  return "unknown";
}

PcgSolver::PcgSolver(PcgOptions options) : options_(options) {}
PcgSolver::~PcgSolver() = default;

std::string PcgSolver::name() const {
  return std::string("pcg-") + to_string(options_.preconditioner);
}

void PcgSolver::set_options(const PcgOptions& options) {
  const bool rebuild = options.preconditioner != options_.preconditioner;
  options_ = options;
  if (rebuild && have_matrix_) {
    ic_.reset();  // a new preconditioner kind needs its own pattern analysis
    const SolveReport r = build_preconditioner();
    matrix_status_ = r.status;
    matrix_message_ = r.message;
  }
}

void PcgSolver::set_preconditioner(Preconditioner preconditioner) {
  external_ = std::move(preconditioner);
}

void PcgSolver::multiply(const ConstMatrixRef& X, MatrixXd& Y) const {
  symmetric_multiply(A_, X, Y);
}

SolveReport PcgSolver::build_preconditioner() {
  SolveReport rep;
  const Index n = A_.rows();
  auto fail = [&](SolveStatus s, std::string m) {
    rep.status = s;
    rep.message = std::move(m);
    return rep;
  };
  // The diagonal is needed by Jacobi, and IC needs every diagonal entry present in the pattern.
  VectorXd diag = VectorXd::Zero(n);
  for (Index j = 0; j < n; ++j)
    for (int p = A_.outerIndexPtr()[j]; p < A_.outerIndexPtr()[j + 1]; ++p)
      if (A_.innerIndexPtr()[p] == j) diag[j] = A_.valuePtr()[p];

  switch (options_.preconditioner) {
    case PcgPreconditioner::none:
    case PcgPreconditioner::external:
      ic_.reset();
      break;
    case PcgPreconditioner::jacobi:
      ic_.reset();
      inv_diag_.resize(n);
      for (Index j = 0; j < n; ++j) {
        if (!(diag[j] > 0.0))
          return fail(SolveStatus::not_positive_definite, "non-positive diagonal entry " +
                                                              std::to_string(diag[j]) + " at row " +
                                                              std::to_string(j));
        inv_diag_[j] = 1.0 / diag[j];
      }
      break;
    case PcgPreconditioner::incomplete_cholesky: {
      for (Index j = 0; j < n; ++j)
        if (!(diag[j] > 0.0))
          return fail(SolveStatus::not_positive_definite, "non-positive diagonal entry " +
                                                              std::to_string(diag[j]) + " at row " +
                                                              std::to_string(j));
      // The AMD ordering depends on the pattern only; set_matrix drops ic_ when it changes.
      if (!ic_) {
        ic_ = std::make_unique<
            Eigen::IncompleteCholesky<double, Eigen::Lower, Eigen::AMDOrdering<int>>>();
        ic_->analyzePattern(A_);
      }
      // Eigen raises the diagonal shift until the incomplete factorization succeeds; a
      // failure left after that is a breakdown we report, not a crash.
      ic_->factorize(A_);
      if (ic_->info() != Eigen::Success) {
        ic_.reset();
        return fail(SolveStatus::not_positive_definite, "incomplete Cholesky breakdown");
      }
      break;
    }
  }
  return rep;
}

bool PcgSolver::keeps_pattern(const SparseRef& A, std::uint64_t key) {
  const bool sized =
      A_.rows() == A.rows() && A_.cols() == A.cols() && A_.nonZeros() == A.nonZeros();
  return kept_.same(sized, key, [&] { return same_pattern(A, A_); });
}

SolveReport PcgSolver::set_matrix(const SparseMatrix& A, HierarchyView hierarchy) {
  SolveReport rep;
  auto fail = [&](SolveStatus s, std::string m) {
    matrix_status_ = s;
    matrix_message_ = m;
    rep.status = s;
    rep.message = std::move(m);
    return rep;
  };
  have_matrix_ = false;
  if (A.rows() != A.cols()) return fail(SolveStatus::failed, "matrix is not square");
  if (!A.isCompressed()) {
    SparseMatrix C = A;
    C.makeCompressed();
    return set_matrix(C, hierarchy);
  }
  if (keeps_pattern(A, hierarchy.pattern_key)) {
    // Same pattern (every time step of a tracked flow): refresh values only.
    std::copy(A.valuePtr(), A.valuePtr() + A.nonZeros(), A_.valuePtr());
  } else {
    A_ = A;
    A_.makeCompressed();
    ic_.reset();
  }
  return matrix_in_place();
}

SolveReport PcgSolver::set_matrix_sum(double a, const SparseRef& M, double b, const SparseRef& K,
                                      HierarchyView hierarchy) {
  // Off one pattern (the general sum) or not square (set_matrix says so): the default.
  if (!summable(M, K) || M.rows() != M.cols())
    return LinearSolver::set_matrix_sum(a, M, b, K, hierarchy);
  have_matrix_ = false;
  // The sum straight into A_ (the copy set_matrix would make), compared as set_matrix compares.
  if (!keeps_pattern(M, hierarchy.pattern_key)) {
    A_ = M;
    ic_.reset();
  }
  sum_on_pattern(a, M, b, K, A_);
  return matrix_in_place();
}

SolveReport PcgSolver::matrix_in_place() {
  // Checked in the copy, so both entries share it. NaN/inf would make the iteration meaningless.
  for (Index p = 0; p < A_.nonZeros(); ++p)
    if (!std::isfinite(A_.valuePtr()[p])) {
      matrix_status_ = SolveStatus::numerical_issue;
      matrix_message_ = "matrix has NaN/inf";
      SolveReport rep;
      rep.status = matrix_status_;
      rep.message = matrix_message_;
      return rep;
    }
  have_matrix_ = true;
  const SolveReport pre = build_preconditioner();
  matrix_status_ = pre.status;
  matrix_message_ = pre.message;
  return pre;
}

void PcgSolver::apply_preconditioner(const MatrixXd& r, MatrixXd& z) const {
  const Index n = r.rows(), k = r.cols();
  z.resize(n, k);
  switch (options_.preconditioner) {
    case PcgPreconditioner::none:
      z = r;
      break;
    case PcgPreconditioner::jacobi:
      for_chunks(n, [&](Index, Index b, Index e) {
        for (Index c = 0; c < k; ++c)
          for (Index i = b; i < e; ++i) z(i, c) = inv_diag_[i] * r(i, c);
      });
      break;
    case PcgPreconditioner::incomplete_cholesky:
      z = ic_->solve(r);
      break;
    case PcgPreconditioner::external:
      external_(r, z);
      break;
  }
}

SolveReport PcgSolver::solve_in_place(const ConstMatrixRef& B, MatrixRef X) {
  SolveReport rep;
  if (!have_matrix_ || matrix_status_ != SolveStatus::converged) {
    rep.status = matrix_status_;
    rep.message = matrix_message_;
    return rep;
  }
  const Index n = A_.rows(), k = B.cols();
  if (B.rows() != n) {
    rep.status = SolveStatus::failed;
    rep.message = "right-hand side has wrong size";
    return rep;
  }
  if (options_.preconditioner == PcgPreconditioner::external && !external_) {
    rep.status = SolveStatus::failed;
    rep.message = "external preconditioner selected but none set";
    return rep;
  }
  const double tol = options_.relative_tolerance;

  VectorXd bnorm;
  column_dots(B, B, bnorm);
  bnorm = bnorm.cwiseSqrt();

  MatrixXd R(n, k), Z(n, k), P(n, k), Q(n, k);
  VectorXd res(k), rz(k), pq(k), rr(k);

  // R = B - A X, the true residual; per column relative residual.
  auto true_residual = [&]() {
    multiply(X, Q);
    for_chunks(n, [&](Index, Index b, Index e) {
      for (Index c = 0; c < k; ++c)
        for (Index i = b; i < e; ++i) R(i, c) = B(i, c) - Q(i, c);
    });
    column_dots(R, R, rr);
    for (Index c = 0; c < k; ++c)
      res[c] = bnorm[c] > 0.0 ? std::sqrt(rr[c]) / bnorm[c] : std::sqrt(rr[c]);
  };
  auto max_res = [&]() {
    double m = 0.0;
    for (Index c = 0; c < k; ++c) {
      if (!std::isfinite(res[c])) return res[c];
      m = std::max(m, res[c]);
    }
    return m;
  };

  // A zero right-hand side has the exact solution 0; CG's ratios would be 0/0 on it.
  for (Index c = 0; c < k; ++c)
    if (bnorm[c] == 0.0) X.col(c).setZero();
  true_residual();

  std::vector<char> active(static_cast<std::size_t>(k), 0);
  auto start_columns = [&](const std::vector<char>& which) -> bool {
    // (Re)starts CG on the listed columns from the current R: p = z = M^{-1} r.
    apply_preconditioner(R, Z);
    column_dots(R, Z, rz);
    for (Index c = 0; c < k; ++c) {
      if (!which[static_cast<std::size_t>(c)]) continue;
      P.col(c) = Z.col(c);
      active[static_cast<std::size_t>(c)] = 1;
    }
    return true;
  };

  std::vector<char> start(static_cast<std::size_t>(k), 0);
  bool any = false;
  for (Index c = 0; c < k; ++c) {
    start[static_cast<std::size_t>(c)] = (bnorm[c] > 0.0 && !(res[c] <= tol)) ? 1 : 0;
    any = any || start[static_cast<std::size_t>(c)];
  }
  rep.relative_residual = max_res();
  if (!std::isfinite(rep.relative_residual)) {
    rep.status = SolveStatus::numerical_issue;
    rep.message = "NaN/inf in the initial residual";
    return rep;
  }
  if (!any) return rep;  // warm start already converged: 0 iterations
  start_columns(start);

  VectorXd alpha(k), beta(k);
  auto finish = [&](SolveStatus s, std::string msg) {
    rep.status = s;
    rep.message = std::move(msg);
    return rep;
  };

  for (int it = 0; it < options_.max_iterations; ++it) {
    for (Index c = 0; c < k; ++c)
      if (active[static_cast<std::size_t>(c)] && !(rz[c] > 0.0))
        return finish(std::isfinite(rz[c]) ? SolveStatus::not_positive_definite
                                           : SolveStatus::numerical_issue,
                      "r^T M^-1 r <= 0: preconditioner not positive definite");

    multiply(P, Q);
    column_dots(P, Q, pq);
    for (Index c = 0; c < k; ++c) {
      alpha[c] = 0.0;
      if (!active[static_cast<std::size_t>(c)]) continue;
      if (!std::isfinite(pq[c])) return finish(SolveStatus::numerical_issue, "NaN/inf in p^T A p");
      if (!(pq[c] > 0.0))
        return finish(SolveStatus::not_positive_definite,
                      "p^T A p <= 0: matrix not positive definite");
      alpha[c] = rz[c] / pq[c];
    }

    // Fused update of x and r plus the partial sums of ||r||^2 (one pass over the block).
    {
      const Index chunks = (n + kChunk - 1) / kChunk;
      std::vector<double> partials(static_cast<std::size_t>(chunks * k), 0.0);
      for_chunks(n, [&](Index ch, Index b, Index e) {
        for (Index c = 0; c < k; ++c) {
          if (active[static_cast<std::size_t>(c)]) {
            const double a = alpha[c];
            double* x = X.col(c).data();
            double* r = R.col(c).data();
            const double* p = P.col(c).data();
            const double* q = Q.col(c).data();
            for (Index i = b; i < e; ++i) {
              x[i] += a * p[i];
              r[i] -= a * q[i];
            }
          }
          partials[static_cast<std::size_t>(ch * k + c)] =
              chunk_dot(R.col(c).data(), R.col(c).data(), b, e);
        }
      });
      combine(partials, k, rr);
    }
    for (Index c = 0; c < k; ++c)
      if (active[static_cast<std::size_t>(c)])
        res[c] = bnorm[c] > 0.0 ? std::sqrt(rr[c]) / bnorm[c] : std::sqrt(rr[c]);
    rep.iterations = it + 1;
    rep.residuals.push_back(max_res());
    if (!std::isfinite(rep.residuals.back()))
      return finish(SolveStatus::numerical_issue, "NaN/inf in the residual");

    bool all_done = true;
    for (Index c = 0; c < k; ++c) {
      if (active[static_cast<std::size_t>(c)] && res[c] <= tol)
        active[static_cast<std::size_t>(c)] = 0;
      all_done = all_done && !active[static_cast<std::size_t>(c)];
    }
    if (all_done) {
      // The recursive residual drifts from b - A x; confirm with the true one and restart the
      // columns that are not really there yet (residual replacement).
      true_residual();
      std::fill(start.begin(), start.end(), 0);
      any = false;
      for (Index c = 0; c < k; ++c)
        if (bnorm[c] > 0.0 && !(res[c] <= tol)) start[static_cast<std::size_t>(c)] = 1, any = true;
      rep.residuals.back() = max_res();
      rep.relative_residual = rep.residuals.back();
      if (!any) return rep;
      if (it + 1 >= options_.max_iterations) break;
      start_columns(start);
      continue;
    }
    if (it + 1 >= options_.max_iterations) break;

    apply_preconditioner(R, Z);
    VectorXd rz_new;
    column_dots(R, Z, rz_new);
    if (!all_finite(rz_new))
      return finish(SolveStatus::numerical_issue, "NaN/inf in the preconditioned residual");
    for (Index c = 0; c < k; ++c)
      beta[c] = active[static_cast<std::size_t>(c)] ? rz_new[c] / rz[c] : 0.0;
    for_chunks(n, [&](Index, Index b, Index e) {
      for (Index c = 0; c < k; ++c) {
        if (!active[static_cast<std::size_t>(c)]) continue;
        const double bt = beta[c];
        double* p = P.col(c).data();
        const double* z = Z.col(c).data();
        for (Index i = b; i < e; ++i) p[i] = z[i] + bt * p[i];
      }
    });
    rz = rz_new;
  }

  // Iteration cap: report the true residual of the last iterate.
  true_residual();
  rep.relative_residual = max_res();
  if (!rep.residuals.empty()) rep.residuals.back() = rep.relative_residual;
  if (!std::isfinite(rep.relative_residual))
    return finish(SolveStatus::numerical_issue, "NaN/inf in the residual");
  if (rep.relative_residual <= tol) return rep;
  return finish(SolveStatus::max_iterations,
                "iteration cap " + std::to_string(options_.max_iterations) + " reached");
}

}  // namespace mcf
