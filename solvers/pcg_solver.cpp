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

SolveReport PcgSolver::set_matrix_sum(const MatrixSum& sum, HierarchyView hierarchy) {
  const SparseRef& M = sum.M;
  // Off one pattern (the general sum) or not square (set_matrix says so): the default.
  if (!summable(sum) || M.rows() != M.cols()) return LinearSolver::set_matrix_sum(sum, hierarchy);
  have_matrix_ = false;
  // The sum straight into A_ (the copy set_matrix would make), compared as set_matrix compares.
  if (!keeps_pattern(M, hierarchy.pattern_key)) {
    A_ = M;
    ic_.reset();
  }
  sum_on_pattern(sum, A_);
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

/// One block PCG solve (solve_in_place): k CG recurrences, one per column of B, sharing each
/// pass over A. Columns converge, and restart after a residual replacement, independently.
struct PcgSolver::Recurrence {
  /// What an iteration leaves to the loop: go on, stop with the report, or stop at the cap.
  enum class Next { go_on, done, cap };

  Recurrence(const PcgSolver& solver, Blocks& blocks, const ConstMatrixRef& B, MatrixRef& X)
      : solver(solver),
        B(B),
        X(X),
        n(solver.A_.rows()),
        k(B.cols()),
        tol(solver.options_.relative_tolerance),
        R(blocks.R),
        Z(blocks.Z),
        P(blocks.P),
        Q(blocks.Q),
        res(k),
        rz(k),
        pq(k),
        rr(k),
        alpha(k),
        beta(k),
        active(static_cast<std::size_t>(k), 0),
        start(static_cast<std::size_t>(k), 0) {
    for (MatrixXd* block : {&R, &Z, &P, &Q}) block->resize(n, k);
    column_dots(B, B, bnorm);
    bnorm = bnorm.cwiseSqrt();
  }

  bool is_active(Index c) const { return active[static_cast<std::size_t>(c)] != 0; }

  /// R = B - A X, the true residual; per column relative residual.
  void true_residual() {
    solver.multiply(X, Q);
    for_chunks(n, [&](Index, Index b, Index e) {
      for (Index c = 0; c < k; ++c)
        for (Index i = b; i < e; ++i) R(i, c) = B(i, c) - Q(i, c);
    });
    column_dots(R, R, rr);
    for (Index c = 0; c < k; ++c)
      res[c] = bnorm[c] > 0.0 ? std::sqrt(rr[c]) / bnorm[c] : std::sqrt(rr[c]);
  }

  /// The worst column's relative residual (the first non-finite one, if any).
  double max_res() const {
    double m = 0.0;
    for (Index c = 0; c < k; ++c) {
      if (!std::isfinite(res[c])) return res[c];
      m = std::max(m, res[c]);
    }
    return m;
  }

  /// Marks in `start` the columns not yet at the tolerance (a zero right-hand side never is
  /// started: its exact solution is 0); returns whether there is one.
  bool mark_unconverged() {
    bool any = false;
    for (Index c = 0; c < k; ++c) {
      start[static_cast<std::size_t>(c)] = (bnorm[c] > 0.0 && !(res[c] <= tol)) ? 1 : 0;
      any = any || start[static_cast<std::size_t>(c)];
    }
    return any;
  }

  /// (Re)starts CG on the columns marked in `start` from the current R: p = z = M^{-1} r.
  void start_columns() {
    solver.apply_preconditioner(R, Z);
    column_dots(R, Z, rz);
    for (Index c = 0; c < k; ++c) {
      if (!start[static_cast<std::size_t>(c)]) continue;
      P.col(c) = Z.col(c);
      active[static_cast<std::size_t>(c)] = 1;
    }
  }

  /// The initial residual. Returns false when there is nothing to iterate: a warm start at the
  /// tolerance already (0 iterations), or NaN/inf (numerical_issue in `rep`).
  bool begin(SolveReport& rep) {
    // A zero right-hand side has the exact solution 0; CG's ratios would be 0/0 on it.
    for (Index c = 0; c < k; ++c)
      if (bnorm[c] == 0.0) X.col(c).setZero();
    true_residual();
    const bool any = mark_unconverged();
    rep.relative_residual = max_res();
    initial = rep.relative_residual;
    if (!std::isfinite(rep.relative_residual)) {
      rep.status = SolveStatus::numerical_issue;
      rep.message = "NaN/inf in the initial residual";
      return false;
    }
    if (!any) return false;
    start_columns();
    return true;
  }

  /// alpha = r^T z / p^T A p per active column, after Q = A P; false on a breakdown (in `rep`).
  bool step_lengths(SolveReport& rep) {
    for (Index c = 0; c < k; ++c)
      if (is_active(c) && !(rz[c] > 0.0))
        return fail(rep,
                    std::isfinite(rz[c]) ? SolveStatus::not_positive_definite
                                         : SolveStatus::numerical_issue,
                    "r^T M^-1 r <= 0: preconditioner not positive definite");
    solver.multiply(P, Q);
    column_dots(P, Q, pq);
    for (Index c = 0; c < k; ++c) {
      alpha[c] = 0.0;
      if (!is_active(c)) continue;
      if (!std::isfinite(pq[c]))
        return fail(rep, SolveStatus::numerical_issue, "NaN/inf in p^T A p");
      if (!(pq[c] > 0.0))
        return fail(rep, SolveStatus::not_positive_definite,
                    "p^T A p <= 0: matrix not positive definite");
      alpha[c] = rz[c] / pq[c];
    }
    return true;
  }

  /// Fused update of x and r plus the partial sums of ||r||^2 (one pass over the block), then
  /// the active columns' relative residuals.
  void update_iterates() {
    const Index chunks = (n + kChunk - 1) / kChunk;
    std::vector<double> partials(static_cast<std::size_t>(chunks * k), 0.0);
    for_chunks(n, [&](Index ch, Index b, Index e) {
      for (Index c = 0; c < k; ++c) {
        if (is_active(c)) {
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
    for (Index c = 0; c < k; ++c)
      if (is_active(c)) res[c] = bnorm[c] > 0.0 ? std::sqrt(rr[c]) / bnorm[c] : std::sqrt(rr[c]);
  }

  /// Deactivates the columns at the tolerance; returns whether none is left active.
  bool retire_converged() {
    bool all_done = true;
    for (Index c = 0; c < k; ++c) {
      if (is_active(c) && res[c] <= tol) active[static_cast<std::size_t>(c)] = 0;
      all_done = all_done && !is_active(c);
    }
    return all_done;
  }

  /// p = z + beta p with z = M^{-1} r and beta = r^T z (new) / r^T z (old); false on NaN/inf.
  bool update_directions(SolveReport& rep) {
    solver.apply_preconditioner(R, Z);
    VectorXd rz_new;
    column_dots(R, Z, rz_new);
    if (!all_finite(rz_new))
      return fail(rep, SolveStatus::numerical_issue, "NaN/inf in the preconditioned residual");
    for (Index c = 0; c < k; ++c) beta[c] = is_active(c) ? rz_new[c] / rz[c] : 0.0;
    for_chunks(n, [&](Index, Index b, Index e) {
      for (Index c = 0; c < k; ++c) {
        if (!is_active(c)) continue;
        const double bt = beta[c];
        double* p = P.col(c).data();
        const double* z = Z.col(c).data();
        for (Index i = b; i < e; ++i) p[i] = z[i] + bt * p[i];
      }
    });
    rz = rz_new;
    return true;
  }

  /// Iteration `it` (0-based).
  Next iterate(int it, SolveReport& rep) {
    const int cap = solver.options_.max_iterations;
    if (!step_lengths(rep)) return Next::done;
    update_iterates();
    rep.iterations = it + 1;
    rep.residuals.push_back(max_res());
    if (!std::isfinite(rep.residuals.back())) {
      fail(rep, SolveStatus::numerical_issue, "NaN/inf in the residual");
      return Next::done;
    }
    if (retire_converged()) {
      // The recursive residual drifts from b - A x; confirm with the true one and restart the
      // columns that are not really there yet (residual replacement).
      true_residual();
      const bool any = mark_unconverged();
      rep.residuals.back() = max_res();
      rep.relative_residual = rep.residuals.back();
      if (!any) return Next::done;
      if (it + 1 >= cap) return Next::cap;
      start_columns();
      return Next::go_on;
    }
    if (it + 1 >= cap) return Next::cap;
    if (off_course(it + 1, rep)) return Next::cap;
    return update_directions(rep) ? Next::go_on : Next::done;
  }

  /// give_up_off_course: whether the mean reduction over the `done` iterations so far, r_i =
  /// r_0 · q^i, needs more than the cap to reach the tolerance.
  bool off_course(int done, const SolveReport& rep) const {
    if (!solver.options_.give_up_off_course || done < 3 || !(initial > 0.0)) return false;
    const double now = rep.residuals.back();
    const double q = std::pow(now / initial, 1.0 / done);
    if (!(q < 1.0)) return true;
    const double more = std::log(tol / now) / std::log(q);
    return done + more > solver.options_.max_iterations;
  }

  /// The iteration cap: the report of the last iterate's true residual.
  SolveReport at_cap(SolveReport& rep) {
    true_residual();
    rep.relative_residual = max_res();
    if (!rep.residuals.empty()) rep.residuals.back() = rep.relative_residual;
    if (!std::isfinite(rep.relative_residual))
      fail(rep, SolveStatus::numerical_issue, "NaN/inf in the residual");
    else if (!(rep.relative_residual <= tol))
      fail(rep, SolveStatus::max_iterations,
           rep.iterations < solver.options_.max_iterations
               ? "on course to miss the tolerance within the cap of " +
                     std::to_string(solver.options_.max_iterations) + ": stopped after " +
                     std::to_string(rep.iterations)
               : "iteration cap " + std::to_string(solver.options_.max_iterations) + " reached");
    return rep;
  }

  static bool fail(SolveReport& rep, SolveStatus s, std::string message) {
    rep.status = s;
    rep.message = std::move(message);
    return false;
  }

  const PcgSolver& solver;
  const ConstMatrixRef& B;
  MatrixRef& X;
  const Index n, k;
  const double tol;
  double initial = 0.0;  ///< the start's relative residual (begin)
  VectorXd bnorm;
  MatrixXd &R, &Z, &P, &Q;  // the solver's blocks_
  VectorXd res, rz, pq, rr, alpha, beta;
  std::vector<char> active, start;
};

SolveReport PcgSolver::solve_in_place(const ConstMatrixRef& B, MatrixRef X) {
  SolveReport rep;
  if (!have_matrix_ || matrix_status_ != SolveStatus::converged) {
    rep.status = matrix_status_;
    rep.message = matrix_message_;
    return rep;
  }
  if (B.rows() != A_.rows()) {
    Recurrence::fail(rep, SolveStatus::failed, "right-hand side has wrong size");
    return rep;
  }
  if (options_.preconditioner == PcgPreconditioner::external && !external_) {
    Recurrence::fail(rep, SolveStatus::failed, "external preconditioner selected but none set");
    return rep;
  }
  Recurrence cg(*this, blocks_, B, X);
  if (!cg.begin(rep)) return rep;
  for (int it = 0; it < options_.max_iterations; ++it) {
    const Recurrence::Next next = cg.iterate(it, rep);
    if (next == Recurrence::Next::done) return rep;
    if (next == Recurrence::Next::cap) break;
  }
  return cg.at_cap(rep);
}

}  // namespace mcf
