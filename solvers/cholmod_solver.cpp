#include "solvers/cholmod_solver.h"

#include "solvers/blas_threads.h"

#include <algorithm>
#include <cmath>

namespace mcf {
namespace {

// The whole file uses the long-integer API (cholmod_l_*): factors of ~1M-vertex systems can
// approach the 2^31-entry limit of the int API, and the index copy into the cached lower
// triangle happens once per pattern either way.
using Long = SuiteSparse_long;

// CHOLMOD's default reaction to errors is to print (Common->print > 0) and call a user handler;
// it never aborts, but the flows must stay silent and decide from the status themselves
// (a non-SPD matrix means the flow turned singular: docs/flow.md "Singular flows").
void silent_error_handler(int /*status*/, const char* /*file*/, int /*line*/,
                          const char* /*message*/) {}

SolveReport make_report(SolveStatus status, std::string message = {}) {
  SolveReport r;
  r.status = status;
  r.message = std::move(message);
  return r;
}

}  // namespace

CholmodSolver::CholmodSolver(int blas_threads) : blas_threads_(blas_threads) {
  cholmod_l_start(&common_);
  common_.supernodal = CHOLMOD_SUPERNODAL;
  common_.print = 0;
  common_.error_handler = &silent_error_handler;
  // On a non-positive pivot stop at once: the factor is useless and the caller only needs
  // the status (faster failure for the singular-flow case).
  common_.quick_return_if_not_posdef = 1;
}

CholmodSolver::~CholmodSolver() {
  free_all();
  cholmod_l_finish(&common_);
}

void CholmodSolver::free_all() {
  if (factor_) cholmod_l_free_factor(&factor_, &common_);
  if (lower_) cholmod_l_free_sparse(&lower_, &common_);
  if (x_) cholmod_l_free_dense(&x_, &common_);
  if (y_) cholmod_l_free_dense(&y_, &common_);
  if (e_) cholmod_l_free_dense(&e_, &common_);
  if (r_) cholmod_l_free_dense(&r_, &common_);
}

std::string CholmodSolver::version() {
  return "CHOLMOD " + std::to_string(CHOLMOD_MAIN_VERSION) + "." +
         std::to_string(CHOLMOD_SUB_VERSION) + "." + std::to_string(CHOLMOD_SUBSUB_VERSION);
}

int CholmodSolver::blas_threads_for(std::int64_t unknowns) const {
  const int cap = mcf::blas_threads();
  if (blas_threads_ == kKeepBlasThreads) return cap;
  if (blas_threads_ == kAutoBlasThreads) return auto_blas_threads(cap, unknowns);
  return std::min(blas_threads_, cap);
}

std::vector<std::pair<std::string, std::string>> CholmodSolver::settings() const {
  if (blas_threads_used_ == 0) return {};
  return {{"blas_threads", std::to_string(blas_threads_used_)}};
}

std::int64_t CholmodSolver::factor_nonzeros() const {
  if (!factor_) return 0;
  if (factor_->is_super) return static_cast<std::int64_t>(factor_->xsize);
  return static_cast<std::int64_t>(factor_->nzmax);
}

bool CholmodSolver::same_pattern(const SparseRef& A) const {
  // The caller has checked that A has the cached pattern's size and number of nonzeros.
  // Exact, and exactly what the factor depends on: every lower-triangle entry of A must be the
  // cached entry at the same place of lower_ (same column, same row) and sit at the position
  // gather_ reads it from. Then the gather forms A's lower triangle, which is all CHOLMOD reads
  // (stype = -1), whatever A's upper triangle holds; a column with an entry more or fewer, or
  // any shift of positions, fails. O(nnz) integer compares, negligible next to the numeric
  // factorization, and unlike a hash it can never wrongly reuse a symbolic analysis.
  const int* outer = A.outerIndexPtr();
  const int* inner = A.innerIndexPtr();
  const auto* p = static_cast<const Long*>(lower_->p);
  const auto* i = static_cast<const Long*>(lower_->i);
  for (Long j = 0; j < rows_; ++j) {
    Long pos = p[j];
    for (int k = outer[j]; k < outer[j + 1]; ++k) {
      if (inner[k] < j) continue;
      if (pos == p[j + 1] || i[pos] != inner[k] || gather_[static_cast<std::size_t>(pos)] != k)
        return false;
      ++pos;
    }
    if (pos != p[j + 1]) return false;
  }
  return true;
}

void CholmodSolver::build_lower(const SparseRef& A) {
  const Long n = A.rows();
  const int* outer = A.outerIndexPtr();
  const int* inner = A.innerIndexPtr();
  Long lower_nnz = 0;
  bool sorted = true;
  for (Long j = 0; j < n; ++j)
    for (int k = outer[j]; k < outer[j + 1]; ++k) {
      if (inner[k] >= j) ++lower_nnz;
      if (k > outer[j] && inner[k] <= inner[k - 1]) sorted = false;
    }

  lower_ = cholmod_l_allocate_sparse(n, n, lower_nnz, sorted ? 1 : 0, /*packed=*/1,
                                     /*stype=*/-1, CHOLMOD_REAL, &common_);
  if (!lower_) return;
  auto* p = static_cast<Long*>(lower_->p);
  auto* i = static_cast<Long*>(lower_->i);
  gather_.resize(static_cast<std::size_t>(lower_nnz));
  Long pos = 0;
  for (Long j = 0; j < n; ++j) {
    p[j] = pos;
    for (int k = outer[j]; k < outer[j + 1]; ++k)
      if (inner[k] >= j) {
        i[pos] = inner[k];
        gather_[static_cast<std::size_t>(pos)] = k;
        ++pos;
      }
  }
  p[n] = pos;

  rows_ = n;
  nonzeros_ = A.nonZeros();
}

SolveReport CholmodSolver::fail(SolveStatus status, std::string message) {
  last_status_ = status;
  last_message_ = message;
  return make_report(status, std::move(message));
}

template <class Fill>
SolveReport CholmodSolver::factorize(const SparseRef& A, std::uint64_t key, Fill fill) {
  // A key vouches for A's pattern, else it is compared exactly (KeptPattern, linear_solver.h).
  const bool sized = lower_ && A.rows() == rows_ && A.nonZeros() == nonzeros_;
  if (!kept_.same(sized, key, [&] { return same_pattern(A); })) {
    free_all();
    rows_ = -1;
    build_lower(A);
    if (!lower_) return fail(SolveStatus::failed, "cholmod_allocate_sparse failed");
    // The analysis reads the pattern alone: the values are filled below.
    factor_ = cholmod_l_analyze(lower_, &common_);
    if (!factor_ || common_.status < CHOLMOD_OK) {
      rows_ = -1;  // force re-analysis next time
      return fail(SolveStatus::failed,
                  "cholmod_analyze failed (status " + std::to_string(common_.status) + ")");
    }
    ++analyses_;
  }
  // NaN/inf would make the factorization's outcome unpredictable (LAPACK's potrf does not
  // reliably flag NaN pivots), so they are refused before it.
  if (!fill(static_cast<double*>(lower_->x), gather_.data(), gather_.size()))
    return fail(SolveStatus::numerical_issue, "matrix has NaN/inf");

  const ScopedBlasThreads blas(blas_threads_for(A.rows()));
  blas_threads_used_ = mcf::blas_threads();
  const int ok = cholmod_l_factorize(lower_, factor_, &common_);
  ++factorizations_;
  const Long n = static_cast<Long>(A.rows());
  if (common_.status == CHOLMOD_NOT_POSDEF || (ok && static_cast<Long>(factor_->minor) < n)) {
    return fail(SolveStatus::not_positive_definite, "matrix not positive definite (pivot " +
                                                        std::to_string(factor_->minor) + " of " +
                                                        std::to_string(n) + ")");
  }
  if (!ok || common_.status < CHOLMOD_OK) {
    return fail(SolveStatus::failed,
                "cholmod_factorize failed (status " + std::to_string(common_.status) + ")");
  }
  factor_ok_ = true;
  last_status_ = SolveStatus::converged;
  last_message_.clear();
  SolveReport r;
  r.status = SolveStatus::converged;
  return r;
}

SolveReport CholmodSolver::set_matrix(const SparseMatrix& A, HierarchyView hierarchy) {
  factor_ok_ = false;
  if (A.rows() != A.cols()) return fail(SolveStatus::failed, "matrix is not square");
  if (!A.isCompressed()) {
    // Rare path (callers are asked for compressed storage); a compressed copy keeps the
    // pattern comparison and the gather simple.
    SparseMatrix C = A;
    C.makeCompressed();
    return set_matrix(C, hierarchy);
  }
  // Every entry is checked, the upper triangle's too, as given.
  const double* v = A.valuePtr();
  for (Eigen::Index k = 0; k < A.nonZeros(); ++k)
    if (!std::isfinite(v[k])) return fail(SolveStatus::numerical_issue, "matrix has NaN/inf");
  return factorize(A, hierarchy.pattern_key, [v](double* x, const int* gather, std::size_t count) {
    for (std::size_t e = 0; e < count; ++e) x[e] = v[gather[e]];
    return true;
  });
}

SolveReport CholmodSolver::set_matrix_sum(const MatrixSum& sum, HierarchyView hierarchy) {
  // Off one pattern: the default forms Eigen's general sum and calls set_matrix.
  if (!summable(sum)) return LinearSolver::set_matrix_sum(sum, hierarchy);
  const SparseRef& M = sum.M;
  factor_ok_ = false;
  if (M.rows() != M.cols()) return fail(SolveStatus::failed, "matrix is not square");
  // a M + b K straight into the lower triangle the factorization reads, no full sum kept (it would
  // be as large as M); each entry is sum_entry's, so the factor is bitwise that of set_matrix on
  // sum_on_pattern's result. Only the lower triangle is formed, so only it is checked for NaN/inf
  // (M and K are symmetric).
  return factorize(M, hierarchy.pattern_key,
                   [&sum](double* x, const int* gather, std::size_t count) {
                     bool finite = true;
                     for (std::size_t e = 0; e < count; ++e) {
                       x[e] = sum.entry(gather[e]);
                       finite = finite && std::isfinite(x[e]);
                     }
                     return finite;
                   });
}

SolveReport CholmodSolver::solve_in_place(const ConstMatrixRef& B, MatrixRef X) {
  if (!factor_ok_) return make_report(last_status_, last_message_);
  const Long n = rows_;
  const Long k = B.cols();
  if (B.rows() != n) return make_report(SolveStatus::failed, "right-hand side has wrong size");
  SolveReport report;
  report.iterations = 1;
  if (k == 0) {
    report.residuals = {0.0};
    return report;
  }

  // Wrap B without copying (its leading dimension is its column stride); CHOLMOD only reads it.
  const Long ldb = B.outerStride();
  cholmod_dense b{};
  b.nrow = static_cast<size_t>(n);
  b.ncol = static_cast<size_t>(k);
  b.nzmax = static_cast<size_t>(ldb * k);  // as if allocated d x ncol; CHOLMOD reads nrow a column
  b.d = static_cast<size_t>(ldb);
  b.x = const_cast<double*>(B.data());
  b.z = nullptr;
  b.xtype = CHOLMOD_REAL;
  b.dtype = CHOLMOD_DOUBLE;

  // All columns in one call; solve2 reuses x_/y_/e_ across calls instead of reallocating.
  const ScopedBlasThreads blas(blas_threads_for(n));
  if (!cholmod_l_solve2(CHOLMOD_A, factor_, &b, nullptr, &x_, nullptr, &y_, &e_, &common_) || !x_)
    return make_report(SolveStatus::failed,
                       "cholmod_solve failed (status " + std::to_string(common_.status) + ")");

  const auto* xs = static_cast<const double*>(x_->x);
  for (Long c = 0; c < k; ++c)
    std::copy(xs + c * static_cast<Long>(x_->d), xs + c * static_cast<Long>(x_->d) + n,
              X.col(c).data());

  // True residual r = b - A x through the cached lower triangle (sdmult honours stype, so no
  // copy of the full A is kept).
  if (!cholmod_l_ensure_dense(&r_, n, k, n, CHOLMOD_REAL, &common_))
    return make_report(SolveStatus::failed, "cholmod_ensure_dense failed");
  auto* rs = static_cast<double*>(r_->x);
  for (Long c = 0; c < k; ++c) std::copy(B.col(c).data(), B.col(c).data() + n, rs + c * n);
  double minus_one[2] = {-1.0, 0.0};
  double one[2] = {1.0, 0.0};
  cholmod_l_sdmult(lower_, 0, minus_one, one, x_, r_, &common_);

  report_true_residual(B, Eigen::Map<const Eigen::MatrixXd>(rs, n, k), report);
  return report;
}

}  // namespace mcf
