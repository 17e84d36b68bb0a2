#pragma once
// Sparse direct solver: CHOLMOD supernodal LL^T (docs/design.md "Layers", solvers/).
// The symbolic analysis (fill-reducing ordering + supernodal structure) is the expensive part
// that only depends on the sparsity pattern; the flows keep one pattern for a whole run (tracked
// octree basis, hat basis on a fixed mesh), so it is computed once and only the numeric
// factorization is repeated when set_matrix() sees the same pattern again.

#include "solvers/linear_solver.h"

#include <cstdint>
#include <string>
#include <vector>

#include <suitesparse/cholmod.h>

namespace mcf {

/// OpenBLAS threads while CHOLMOD factorizes and solves (its supernodal updates call the BLAS,
/// which keeps its own pool). The count is taken under the caller's cap (blas_threads() when the
/// call starts: a flow caps it at its `threads`) and restored after each call.
inline constexpr int kKeepBlasThreads = -1;  ///< run at the caller's cap
inline constexpr int kAutoBlasThreads = 0;   ///< auto_blas_threads(cap, unknowns)

class CholmodSolver final : public LinearSolver {
 public:
  /// blas_threads: kKeepBlasThreads, kAutoBlasThreads or a count (at most the caller's cap).
  explicit CholmodSolver(int blas_threads = kKeepBlasThreads);
  ~CholmodSolver() override;
  CholmodSolver(const CholmodSolver&) = delete;
  CholmodSolver& operator=(const CholmodSolver&) = delete;

  std::string name() const override { return "cholmod"; }

  /// Factorizes A (full symmetric storage; only its lower triangle is read). Re-analyzes only
  /// when the pattern differs from the previous call's: compared exactly against the cached
  /// lower triangle, or taken as the same without a comparison when hierarchy.pattern_key
  /// vouches for it (linear_solver.h). Status not_positive_definite when the factorization
  /// meets a non-positive pivot (no abort, no output).
  SolveReport set_matrix(const SparseMatrix& A, HierarchyView hierarchy = {}) override;
  /// set_matrix(a M + b K [+ s S]) for terms on one pattern, formed straight into the cached
  /// lower triangle (bitwise the same factor; no full sum kept). Off one pattern, the default.
  SolveReport set_matrix_sum(const MatrixSum& sum, HierarchyView hierarchy = {}) override;
  using LinearSolver::set_matrix_sum;

  /// Number of symbolic analyses done so far (tests check that refactorization reuses it).
  int analyses() const { return analyses_; }
  /// Number of exact pattern comparisons done so far (a call whose pattern_key vouches for the
  /// pattern skips it; so does a call that must re-analyze anyway).
  int pattern_comparisons() const { return kept_.comparisons(); }
  /// Number of numeric factorizations done so far.
  int factorizations() const { return factorizations_; }
  /// True if the last set_matrix produced a usable factor.
  bool factorized() const { return factor_ok_; }
  /// True once a factor exists and CHOLMOD chose the supernodal form (always, as configured).
  bool is_supernodal() const { return factor_ != nullptr && factor_->is_super != 0; }
  /// Nonzeros in the factor L (0 before the first factorization); useful for memory reports.
  std::int64_t factor_nonzeros() const;

  /// "CHOLMOD x.y.z" of the headers compiled against, for result.json "libraries".
  static std::string version();
  /// The OpenBLAS threads the last factorization ran with, as OpenBLAS reported them (0 before
  /// the first).
  int blas_threads_used() const { return blas_threads_used_; }
  /// {"blas_threads", N} once a factorization ran (result.json "solver_settings").
  std::vector<std::pair<std::string, std::string>> settings() const override;

 protected:
  /// Solves all columns of B in one cholmod_solve call; X's input is ignored. Reports
  /// iterations = 1 and the true relative residual max_c ||b_c - A x_c|| / ||b_c||.
  SolveReport solve_in_place(const ConstMatrixRef& B, MatrixRef X) override;

 private:
  void free_all();
  bool same_pattern(const SparseRef& A) const;  // A of the cached size and nonzeros: exact
  void build_lower(const SparseRef& A);         // new pattern: (re)build the cached lower triangle
  /// Both set_matrix entries: analyzes A's pattern when it is new (key: the caller's
  /// pattern_key), lets `fill(x, gather, count)` write the lower triangle's values (x[e] from
  /// the caller's entry gather[e]; false when one is NaN/inf), then factorizes.
  template <class Fill>
  SolveReport factorize(const SparseRef& A, std::uint64_t key, Fill fill);
  SolveReport fail(SolveStatus status, std::string message);  // records and reports a failure

  cholmod_common common_{};
  cholmod_sparse* lower_ = nullptr;  // cached lower triangle of A (stype = -1)
  cholmod_factor* factor_ = nullptr;
  cholmod_dense* x_ = nullptr;  // solve2 workspaces, reused across solves
  cholmod_dense* y_ = nullptr;
  cholmod_dense* e_ = nullptr;
  cholmod_dense* r_ = nullptr;  // residual workspace

  std::int64_t rows_ = -1;
  std::int64_t nonzeros_ = 0;  // of the full A the cached pattern came from
  KeptPattern kept_;           // the key of the cached pattern, the comparisons made
  // lower_->x[e] = A.valuePtr()[gather_[e]]: refreshing values is one gather, no pattern work.
  // Together with lower_'s own pattern it is also what a new A is compared against, so no copy
  // of A's full pattern is kept. Positions in an int-indexed matrix: int.
  std::vector<int> gather_;

  /// The count for a system of `unknowns` under the current cap (the constructor's rule).
  int blas_threads_for(std::int64_t unknowns) const;

  int blas_threads_ = kKeepBlasThreads;
  int blas_threads_used_ = 0;
  int analyses_ = 0;
  int factorizations_ = 0;
  bool factor_ok_ = false;
  SolveStatus last_status_ = SolveStatus::failed;
  std::string last_message_ = "set_matrix not called";
};

}  // namespace mcf
