#pragma once
// One interface for every linear solver (docs/design.md "Layers": a basis and a solver only meet
// through the system they exchange). A solver is given a sparse symmetric positive-definite
// matrix, optionally with a multigrid hierarchy, and solves several right-hand sides at once.

#include "core/sparse.h"

#include <Eigen/Core>

#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace mcf {

enum class SolveStatus {
  converged,              ///< reached the tolerance (or a direct solve succeeded)
  max_iterations,         ///< stopped at the iteration cap; the answer is the last iterate
  not_positive_definite,  ///< the matrix is not SPD (the flow turned singular); not an abort
  numerical_issue,        ///< NaN/inf met during the solve
  failed                  ///< anything else; see message
};

const char* to_string(SolveStatus s);

/// One right-hand side of a solver that solves the columns one after another (PETSc's KSP).
struct ColumnReport {
  int iterations = 0;
  double relative_residual = 0.0;  ///< the true ||b - A x|| / ||b|| at exit (||r|| when b = 0)
  std::string reason;              ///< why it stopped, in the solver's words (KSPConvergedReason)
};

struct SolveReport {
  SolveStatus status = SolveStatus::converged;
  int iterations = 0;              ///< cycles (multigrid), CG iterations (PCG), 1 (direct)
  double relative_residual = 0.0;  ///< max over right-hand sides of ||b - A x|| / ||b||
  std::vector<double> residuals;   ///< relative residual after each iteration / cycle
  /// Multigrid: the mean reduction of the relative residual per cycle over the solve,
  /// (r_k / r_0)^(1/k) from the warm start's r_0, where the solver measured r_0; -1 otherwise.
  double contraction = -1;
  /// Cycles a guarded multigrid ran beyond its configured count to bring the step under its
  /// residual bound (solvers/multigrid_fallback.h); included in `iterations`.
  int extra_cycles = 0;
  /// Iterations of a fallback solver that took over after this one stalled or ended above its
  /// residual bound (0: none ran).
  int fallback_iterations = 0;
  /// A sparse factorization solved this system after the iterative solver and its fallback did
  /// not (solvers/multigrid_fallback.h).
  bool direct_fallback = false;
  std::string message;
  /// Per right-hand side, from a solver that reports them (PETSc); empty otherwise.
  std::vector<ColumnReport> columns;
  /// What this solve did with its preconditioner, from a solver that says (PETSc: "new",
  /// "refreshed", "kept"); empty otherwise.
  std::string preconditioner_setup;
  bool ok() const {
    return status == SolveStatus::converged || status == SolveStatus::max_iterations;
  }
};

/// Multigrid hierarchy as plain arrays (levels ordered coarsest first; the finest level is the
/// system's own). prolongations[l] maps level l to level l+1, so there are levels-1 of them.
/// colours[l][i] in 0..7 is the Gauss-Seidel colour of function i on level l: functions of the
/// same colour never couple (octree parity colouring, docs/octree-multigrid.md).
///
/// pattern_key: 0, or a key from new_pattern_key() by which the caller vouches that A's sparsity
/// pattern, the prolongations (pattern and values) and the colours are exactly those of the
/// previous set_matrix call that carried the same key (PETSc's SAME_NONZERO_PATTERN). A solver
/// may then skip comparing them; with 0 or a new key it compares. Only a caller that owns a fixed
/// pattern (the tracked basis through ReducedSystem) should pass one.
struct HierarchyView {
  const std::vector<SparseMatrix>* prolongations = nullptr;
  const std::vector<std::vector<std::uint8_t>>* colours = nullptr;
  std::uint64_t pattern_key = 0;
  bool empty() const { return prolongations == nullptr || prolongations->empty(); }
};

/// A key never returned before in this process (thread-safe); never 0.
std::uint64_t new_pattern_key();

/// What a direct or Krylov solver keeps to tell whether a new matrix has the pattern it holds:
/// the pattern_key it was last given, and a count of exact comparisons (tests read it). One rule
/// for all of them: the O(1) checks (`sized`: size and number of nonzeros) are never skipped, so
/// a stale key on a matrix of another size still means a new pattern; past them, the key of the
/// previous call vouches, and anything else is compared. (The multigrid keeps its key only once
/// its levels are built, since a call can fail half-way: multigrid.cpp.)
class KeptPattern {
 public:
  template <class Compare>
  bool same(bool sized, std::uint64_t key, Compare compare) {
    bool same = sized && key != 0 && key == key_;
    if (sized && !same) {
      ++comparisons_;
      same = compare();
    }
    key_ = key;  // later calls with it are vouched for against this call's pattern
    return same;
  }
  int comparisons() const { return comparisons_; }

 private:
  std::uint64_t key_ = 0;
  int comparisons_ = 0;
};

/// Two report messages as one, "; "-separated (either may be empty).
inline std::string joined_messages(const std::string& first, const std::string& more) {
  if (first.empty()) return more;
  if (more.empty()) return first;
  return first + "; " + more;
}

/// Whether two compressed matrices have the same sparsity pattern (size, column starts and row
/// indices compared exactly; values ignored). False when either is not compressed.
bool same_pattern(const SparseRef& A, const SparseRef& B);

/// One entry of a M + b K. Every kernel that forms the system from M and K on one pattern calls
/// this, so they agree bitwise (the multigrid's fused refill and sum_on_pattern below).
inline double sum_entry(double a, double m, double b, double k) {
  return a * m + b * k;
}

/// One entry of a M + b K + s S: the third term is added last, so that without it (s S absent)
/// an entry is bitwise sum_entry(a, m, b, k).
inline double sum_entry(double a, double m, double b, double k, double s, double q) {
  return sum_entry(a, m, b, k) + s * q;
}

/// The system matrix of a flow step as its terms: a M + b K, and for a stabilized increment also
/// s S (docs/octree-multigrid.md, "Stabilization"). The matrices are views of storage the caller
/// keeps alive while the sum is in use; solvers form the entries they need with entry().
struct MatrixSum {
  MatrixSum(double a, const SparseRef& M, double b, const SparseRef& K) : a(a), M(M), b(b), K(K) {}
  MatrixSum(double a, const SparseRef& M, double b, const SparseRef& K, double s,
            const SparseRef& S)
      : a(a), M(M), b(b), K(K), s(s), S(S) {}
  double a;
  SparseRef M;
  double b;
  SparseRef K;
  double s = 0.0;
  std::optional<SparseRef> S;  ///< the third term, if any

  /// Entry p of the value arrays (all terms on one pattern): sum_entry's.
  double entry(Eigen::Index p) const {
    const double v = sum_entry(a, M.valuePtr()[p], b, K.valuePtr()[p]);
    return S ? v + s * S->valuePtr()[p] : v;
  }
};

/// A = a M + b K [+ s S] entry by entry, in parallel, for all terms and A on one pattern
/// (same_pattern: the caller checks; A keeps its pattern and only its values are written). This
/// is how every flow forms its system matrix when the basis assembles its matrices on one
/// pattern.
void sum_on_pattern(const MatrixSum& sum, SparseMatrix& A);
inline void sum_on_pattern(double a, const SparseRef& M, double b, const SparseRef& K,
                           SparseMatrix& A) {
  sum_on_pattern(MatrixSum(a, M, b, K), A);
}

/// The sum for any patterns (Eigen's sum: the union of the patterns; a M alone when b is 0 and
/// there is no third term), compressed.
SparseMatrix general_sum(const MatrixSum& sum);
inline SparseMatrix general_sum(double a, const SparseRef& M, double b, const SparseRef& K) {
  return general_sum(MatrixSum(a, M, b, K));
}

/// Whether M and K may be summed on one pattern as far as O(1) checks tell (compressed, same
/// size and number of nonzeros); same_pattern() is the full comparison, which a caller that owns
/// a fixed pattern makes once.
bool summable(const SparseRef& M, const SparseRef& K);
/// The same for all terms of a sum.
bool summable(const MatrixSum& sum);

/// Dense blocks of right-hand sides and solutions, n x k, column-major (Eigen::Ref: any column
/// stride, so a block of a larger matrix binds as well).
using ConstMatrixRef = Eigen::Ref<const Eigen::MatrixXd>;
using MatrixRef = Eigen::Ref<Eigen::MatrixXd>;

/// A direct solve's true residual R = B - A X into its report: per column ||r|| / ||b|| (||r||
/// when b = 0), the worst over the columns, and numerical_issue when that is not finite. A
/// non-finite column is kept, so a later finite one cannot report the solve converged.
void report_true_residual(const ConstMatrixRef& B, const ConstMatrixRef& R, SolveReport& report);

class LinearSolver {
 public:
  virtual ~LinearSolver() = default;
  virtual std::string name() const = 0;
  /// The largest system this solver takes (the dense reference's n² storage); a flow refuses a
  /// larger basis before its first step, as a configuration error.
  virtual Eigen::Index max_dimension() const { return std::numeric_limits<Eigen::Index>::max(); }
  /// How the solver is set up, as (key, text) pairs that result.json records under
  /// "solver_settings" (PETSc's options and types); empty where the config says it all.
  virtual std::vector<std::pair<std::string, std::string>> settings() const { return {}; }

  /// Sets (or updates) the matrix A (full symmetric storage, compressed). A solver detects
  /// whether the sparsity pattern is unchanged and then reuses its symbolic work.
  /// Returns a report whose status is not_positive_definite when a factorization fails.
  virtual SolveReport set_matrix(const SparseMatrix& A, HierarchyView hierarchy = {}) = 0;

  /// set_matrix(a M + b K [+ s S]) for terms on one pattern (same_pattern: the caller checks; when
  /// summable() does not hold, the default below forms Eigen's general sum, whose pattern is the
  /// union), bitwise the same, without the caller storing the sum (as large as M itself). The
  /// default forms the sum in a matrix this object keeps (the dense reference uses it); the
  /// multigrid, PCG and CHOLMOD solvers override it and write a M + b K straight into the copy they
  /// keep anyway (the multigrid's permuted finest level, PCG's matrix, CHOLMOD's lower triangle).
  virtual SolveReport set_matrix_sum(const MatrixSum& sum, HierarchyView hierarchy = {});
  /// set_matrix_sum of a M + b K.
  SolveReport set_matrix_sum(double a, const SparseRef& M, double b, const SparseRef& K,
                             HierarchyView hierarchy = {}) {
    return set_matrix_sum(MatrixSum(a, M, b, K), hierarchy);
  }

  /// Solves A X = B for all columns of B. X holds the warm start on entry (iterative solvers use
  /// it; direct solvers ignore it) and the solution on exit. Any column-major matrix binds to B and
  /// X without a copy (the flows' n x 3 Coefficients too); X must have B's shape, else the report
  /// is `failed` and X is left alone.
  SolveReport solve(const ConstMatrixRef& B, MatrixRef X);
  /// The same for a resizable X: one of another shape than B's is first set to zero.
  SolveReport solve(const ConstMatrixRef& B, Eigen::MatrixXd& X);

  /// How well the caller predicted the next solve's warm start: θ ∈ [0, 1], the part of an
  /// extrapolated motion that fit the equations (steps/predicted_start.h); negative = no
  /// prediction. It holds for the next solve only. A solver held to a residual bound may keep a
  /// fixed-work answer above the bound where the start fit (FallbackMultigridSolver); the others
  /// ignore it.
  void set_start_fit(double theta) { start_fit_ = theta; }

 protected:
  /// What every solver implements: solve() with X already of B's shape.
  virtual SolveReport solve_in_place(const ConstMatrixRef& B, MatrixRef X) = 0;
  /// The θ of set_start_fit for the solve under way (negative: none given).
  double start_fit() const { return start_fit_; }

 private:
  double start_fit_ = -1;
  SparseMatrix sum_;           // the default set_matrix_sum's a M + b K
  std::uint64_t sum_key_ = 0;  // pattern key of the last call
};

}  // namespace mcf
