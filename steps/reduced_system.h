#pragma once
// Solving (a M + b K) Y = R with some functions held fixed. The basis's locked functions (open
// boundaries, docs/design.md "Conventions") are eliminated, so the system the solver sees stays
// symmetric positive definite. Functions whose row is empty this step (no cubature point
// contributes: the paper's "anchoring" through a pinch) are held too instead of making the matrix
// singular: in place, by a diagonal entry and a matching right-hand side, so the pattern does not
// change with them.
// With no function held (a closed surface) M and K go to the solver as they are
// (LinearSolver::set_matrix_sum), so the sum is not stored here as well.
// The reduced pattern and the restricted hierarchy are rebuilt only when the eliminated set
// changes; the basis's own pattern must stay fixed while a ReducedSystem lives (make a new one
// after a rebuild).

#include "bases/basis.h"
#include "solvers/linear_solver.h"

#include <cstdint>
#include <vector>

namespace mcf {

class ReducedSystem {
 public:
  ReducedSystem(const Basis& basis, LinearSolver& solver);

  /// A third term s S of the system (the normal-gradient stabilization of an increment), S on the
  /// pattern of M and K.
  struct ExtraTerm {
    double s;
    SparseView S;
  };

  /// Solves (a M + b K [+ s S]) Y = R; `report()` then holds the solver's report, its message also
  /// carrying set_matrix's note on an accepted matrix. Returns the full solution. With every
  /// function held the solver is not called: Y is the held values, and the report says
  /// "converged" after 0 iterations with a message saying nothing is free to move. Empty rows are
  /// those of a M + b K; with an extra term they are eliminated instead of held in place (the
  /// term couples them to their neighbours).
  /// An iterative solver's passes: the solve is repeated (each pass continues from the last
  /// iterate, on the same matrix) until the relative residual is at most `tolerance` or `max`
  /// passes ran. One pass when absent.
  struct Passes {
    double tolerance;
    int max;
  };

  Coefficients solve(double a, double b, const Coefficients& R, const Coefficients& fixed_values,
                     const Coefficients& warm, const ExtraTerm* extra = nullptr,
                     const Passes* passes = nullptr);
  const SolveReport& report() const { return report_; }
  /// Functions held in the last solve (boundary + empty rows).
  std::size_t num_fixed() const { return fixed_.size(); }

 private:
  /// What hold_in_place leaves: the functions the reduction leaves out (sorted: the locked
  /// ones, and empty rows without a stored diagonal), the empty rows held in place by a
  /// diagonal d, and d.
  struct Anchors {
    std::vector<int> eliminated;
    std::vector<int> anchored;
    double d = 1.0;
  };

  /// Rows of a M + b K without a nonzero entry this step, but the locked ones (sorted).
  std::vector<int> empty_rows(double a, double b, const SparseView& M, const SparseView& K,
                              bool shared) const;
  /// No function held: the solver gets a M + b K (or sum_) as it is.
  Coefficients solve_whole(const MatrixSum& terms, bool shared, HierarchyView view,
                           const Coefficients& R, const Coefficients& warm);
  /// Sets the diagonal of sum_'s empty rows that have one (the anchoring); the others are left
  /// to the reduction.
  Anchors hold_in_place(const std::vector<int>& empty, bool eliminate_all);
  /// Solves on the free functions of sum_ (the reduction, rebuilt when `eliminated` changed)
  /// with the eliminated ones at their fixed values.
  Coefficients solve_reduced(std::vector<int> eliminated, bool shared, const HierarchyView& view,
                             const Coefficients& R, const Coefficients& warm,
                             const Coefficients& fixed_values);
  void rebuild_reduction(const SparseMatrix& S);
  bool shares_pattern(const SparseRef& M, const SparseRef& K);
  /// report_ holds set_matrix's report: when it is ok, solves into X and keeps its note.
  void solve_after_set(const ConstMatrixRef& R, MatrixRef X);
  Passes passes_{0.0, 1};  // of the solve in progress

  const Basis& basis_;
  LinearSolver& solver_;
  std::vector<int> base_fixed_;  // from the basis (boundary)
  std::vector<int> fixed_;       // sorted; last solve's held functions (locked + empty rows)
  std::vector<int> eliminated_;  // sorted; those the current reduction leaves out
  std::vector<int> free_;        // reduced index -> full index
  std::vector<int> reduced_of_;  // full index -> reduced index or -1
  std::vector<int> source_nz_;   // reduced nonzero -> nonzero of the full matrix
  SparseMatrix sum_;             // a M + b K: only while functions are held (else the solver's)
  SparseMatrix reduced_;
  std::vector<SparseMatrix> prolongations_;  // finest one row-restricted
  std::vector<std::vector<std::uint8_t>> colours_;
  bool reduction_valid_ = false;
  int shares_pattern_ = -1;  // M and K on one pattern? (-1: not yet checked)
  // Pattern keys (HierarchyView::pattern_key): sum_ keeps M's pattern for every (a, b) when M
  // and K share it, and reduced_ keeps its pattern until the fixed set changes.
  std::uint64_t full_key_ = 0, reduced_key_ = 0;
  SolveReport report_;
};

}  // namespace mcf
