#pragma once
// The multigrid solver's state (header solvers/multigrid.h): its levels in their internal
// numbering, each with its operator, transfer, smoother rows and work buffers, and the coarsest
// level's direct solve. MultigridSolver holds one and hands each call to it. Its functions are
// defined by concern:
// - solvers/multigrid_setup.cpp: the hierarchy's set-up (levels, internal numbering, Galerkin
//   patterns and values, diagonals, the smoother's rows, the coarsest factorization), set_up();
// - solvers/multigrid_cycle.cpp: the cycle (V/W recursion, residual, restriction, prolongation,
//   coarsest solve, convergence checks), solve() and precondition();
// - solvers/smoother.cpp: the Gauss-Seidel sweeps that sweep() runs on a level.
//
// Internal to the multigrid solver (namespace multigrid_detail); not part of the solvers'
// interface.

#include "core/sparse.h"
#include "solvers/csc_view.h"
#include "solvers/galerkin.h"
#include "solvers/interleaved_ldlt.h"
#include "solvers/level_ordering.h"
#include "solvers/linear_solver.h"
#include "solvers/multigrid_options.h"
#include "solvers/smoother.h"

#include <Eigen/SparseCholesky>

#include <cstddef>
#include <cstdint>
#include <new>
#include <string>
#include <vector>

namespace mcf::multigrid_detail {

/// Cache-line aligned storage, so that a row's four columns (32 bytes at a multiple of 32) never
/// straddle two cache lines.
template <class T>
struct CacheAligned {
  using value_type = T;
  CacheAligned() = default;
  template <class U>
  CacheAligned(const CacheAligned<U>&) {}
  T* allocate(std::size_t n) {
    return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t(64)));
  }
  void deallocate(T* p, std::size_t) { ::operator delete(p, std::align_val_t(64)); }
  friend bool operator==(const CacheAligned&, const CacheAligned&) { return true; }
};
using Buffer = std::vector<double, CacheAligned<double>>;

struct MultigridState {
  // A level's internal numbering (perm, inv, coloured, segment_start, block_tiles) is its
  // LevelNumbering base (solvers/level_ordering.h).
  struct Level : LevelNumbering {
    // All matrices and buffers of a level are in its internal numbering (tile-wise colour-major
    // when colours were given; see number_by_colour()).
    SparseMatrix A;                  // compressed, symmetric pattern; coarse levels sorted
    std::vector<int> transpose_pos;  // entry e=(i,J) -> position of (J,i) (coarse levels)
    std::vector<double> inv_diag;
    std::vector<int> diag_pos;  // position of the diagonal entry of each column, -1 if none
    // Finest level of a hierarchy: each column stores its diagonal last (the smoother reads the
    // off-diagonal run in place); diag_rank[r] = the diagonal's place in the caller's column
    // (-1: none). Empty on coarse levels and a single level.
    std::vector<int> diag_rank;
    SmootherRows smoother;  // compact off-diagonal rows for the sweeps (may be empty)
    // galerkin_by_term: each term's values on A's pattern (the finest level: the caller's terms
    // in the finest numbering; coarse levels: their Galerkin products). Empty otherwise.
    std::vector<std::vector<double>> terms;
    // Transfer to the next finer level (absent on the finest level).
    SparseMatrix P;          // n_{l+1} x n_l
    SparseMatrix PT;         // n_l x n_{l+1}
    Spa spa;                 // accumulators of the Galerkin product
    GalerkinPlan plan;       // its visits laid out once per pattern (may be empty: galerkin_plan)
    int galerkin_calls = 0;  // products computed on this pattern (plan_for)
    // Work buffers (interleaved n x k, row stride padded to a multiple of 4).
    Buffer x, b, r;
    // Finest level, mixed precision: the iterate and right-hand side kept while a cycle runs on
    // the correction (correction_cycle).
    Buffer saved_x, saved_b;
    int n() const { return int(A.rows()); }
  };

  std::vector<Level> levels;                       // coarsest first
  std::vector<std::vector<std::uint8_t>> colours;  // as given (to detect changes)
  Eigen::SimplicialLDLT<SparseMatrix> ldlt;
  // Its factor as the coarsest solve reads it (one pass over L for four columns), and its work.
  InterleavedLdlt coarse_factor;
  std::vector<double> coarse_work;
  // The coarsest solve when its matrix is only semi-definite (set_matrix: coarsest_pseudo_inverse):
  // a dense generalized inverse, empty while the LDLᵀ factor serves.
  Eigen::MatrixXd coarse_pinv;
  Eigen::MatrixXd coarse_rhs, coarse_sol;
  int k = 0;          // columns the buffers are sized for
  std::size_t s = 0;  // their row stride: k rounded up to a multiple of 4
  bool ready = false;
  bool fine_single = false;  // the finest level's sweeps read single precision (mixed_precision)
  std::int64_t symbolic_builds = 0, numeric_builds = 0, pattern_comparisons = 0;
  // galerkin_refresh: set_matrix calls since the coarse operators were last computed, and how
  // many calls in all kept them; the coarsest level's note (semi-definite) of that computation.
  int calls_since_refresh = 0;
  std::int64_t lagged_refreshes = 0;
  std::string coarse_note;
  std::int64_t term_products = 0;
  // galerkin_by_term: the number of terms the levels' `terms` hold (0: none kept) and which of
  // them changed in this call.
  int term_count = 0;
  std::vector<char> term_changed;
  std::uint64_t pattern_key = 0;  // the key the current pattern was set with (0: none)
  // finest_matrix(): the finest matrix in the caller's numbering, and for each of its entries the
  // position of its value in the finest level's A (empty: not laid out for this pattern); the
  // values are those of set_matrix call `finest_call` (calls counts the calls).
  SparseMatrix finest;
  std::vector<int> finest_from;
  std::int64_t calls = 0, finest_call = -1;
  std::vector<MultigridLevelWork> work;  // per level, coarsest first (level_work())

  // ---- set-up (solvers/multigrid_setup.cpp) ----

  /// MultigridSolver::set_matrix and set_matrix_sum: the finest values are A's, or the sum's when
  /// one is given (A = its M). Builds the levels when the pattern is new, then their values.
  SolveReport set_up(const SparseRef& A, const MatrixSum* sum, HierarchyView hierarchy,
                     const MultigridOptions& options);

  /// The levels' patterns, internal numberings and smoother rows for the finest matrix A (its
  /// values copied too) and the prolongations P (coarsest first); `single`: the finest level's
  /// sweeps read single precision.
  void symbolic(const SparseRef& A, const std::vector<SparseMatrix>& P,
                const std::vector<std::vector<std::uint8_t>>* given_colours, bool single);

  /// Walks the finest matrix's stored entries column by column: put(p, q, out) writes the
  /// caller's entries [p, q) (positions in G, the caller's numbering) at `out` (in `val`, an array
  /// on the finest pattern) and returns the end of what it wrote. The diagonal goes last
  /// (diagonal_last).
  template <class Put>
  void walk_fine(const Csc& G, double* val, const Put& put);

  /// New values of the finest matrix (same pattern as the stored one, in the caller's numbering):
  /// A's, or the sum's entry by entry when one is given (its terms on A's pattern, A its M;
  /// sum_entry, so bitwise what sum_on_pattern would have handed to set_matrix).
  void set_fine_values(const SparseRef& A, const MatrixSum* sum);

  /// galerkin_by_term: the sum's terms into the finest level's `terms`, and which of them changed
  /// (term_changed; bitwise comparison with the kept copy). `fresh`: the levels were just built or
  /// held another number of terms; every level's terms are then sized and all count as changed.
  void set_fine_terms(const MatrixSum& sum, bool fresh);

  /// The Galerkin plan of coarse level l (solvers/galerkin.h), laid out when it will earn back its
  /// cost (multigrid_setup.cpp).
  const GalerkinPlan* plan_for(std::size_t l);

  /// Drops the kept terms (a call without a sum, or without the option).
  void drop_terms();

  /// galerkin_by_term: coarse level l's terms that changed, then its matrix as their sum.
  void coarse_by_term(std::size_t l, const MatrixSum& sum);

  /// Numerical values of all levels from the finest level's values (already in place).
  /// Returns false when a diagonal entry is negative or not finite.
  /// With `by_term` (the sum's terms set by set_fine_terms), coarse levels are refreshed by
  /// term (coarse_by_term).
  /// With `coarse` false (a lagged refresh), only the finest level's diagonal and smoother.
  bool numeric(const MatrixSum* by_term, bool coarse = true);

  /// Whether the LDLᵀ factor of the coarsest matrix is fit to solve with: it succeeded and no
  /// pivot is below 1e-10 of its row's diagonal entry (a dependent function leaves a pivot of
  /// rounding size, whose inverse would fill the solution with a huge null-space component).
  bool coarsest_factor_is_sound() const;

  /// The coarsest matrix's generalized inverse (coarse_pinv), from the eigen-decomposition of its
  /// Jacobi scaling Â = S⁻¹AS⁻¹ (S² = diag A, so a function that barely meets the surface is not
  /// taken for a null direction): A⁺ = S⁻¹ V Λ⁺ Vᵀ S⁻¹, with eigenvalues below 1e-11 λ_max taken
  /// as 0. For a consistent right-hand side (the restriction of a fine residual of a consistent
  /// system) it gives the solution without a null-space component. Returns why it cannot be used
  /// (a negative eigenvalue: the matrix is indefinite; too large to decompose), else "" and the
  /// null space's dimension in `null_dimension`.
  std::string coarsest_pseudo_inverse(int& null_dimension);

  // ---- cycle (solvers/multigrid_cycle.cpp) ----

  /// MultigridSolver::solve_in_place: cycles from the warm start X (see there).
  SolveReport solve(const ConstMatrixRef& B, MatrixRef X, const MultigridOptions& options);

  /// MultigridSolver::precondition: one cycle applied to r from z = 0.
  void precondition(const Eigen::MatrixXd& r, Eigen::MatrixXd& z, const MultigridOptions& options);

  /// Sizes every level's buffers for `cols` right-hand sides (unchanged when they already are).
  void ensure_buffers(int cols);

  /// One Gauss-Seidel sweep on level l (solvers/smoother.h, gauss_seidel_sweep), forward or
  /// reverse.
  void sweep(int l, bool reverse);

  /// r = b - A x on level l.
  void residual(int l);

  /// x = A_0⁻¹ b on the coarsest level (its LDLᵀ factor, or coarse_pinv where that serves).
  void coarse_solve();

  /// Restriction b_C = Pᵀ r_F from level l to l - 1 (gather over the columns of P), and the
  /// coarse level's start x_C = 0, in the same pass over its rows (in parallel, instead of a
  /// serial fill of its own).
  void restrict_residual(int l);

  /// x = 0 on level L, in parallel over its rows.
  void zero_iterate(Level& L);

  /// Prolongation x_F += P x_C from level l - 1 to l (gather over the columns of Pᵀ = rows of P).
  void prolongate(int l);

  /// One V- or W-cycle on level l for its b, from its x (recursing to the coarser levels).
  void cycle(int l, const MultigridOptions& opt);

  /// Runs one cycle on the correction of the finest level's iterate (mixed_precision): from
  /// r = b - A x (computed here unless `have_r`: the finest level's r holds it already), the
  /// cycle solves A e ≈ r from e = 0, and x += e.
  void correction_cycle(const MultigridOptions& opt, bool have_r);

  /// max over columns of ||b - A x|| / ||b|| on the finest level (deterministic reduction). With
  /// `keep`, the residual b - A x is also stored in the finest level's r (what residual() would
  /// write, bitwise: the same terms in the same order).
  double relative_residual(const Eigen::VectorXd& bnorm, bool keep = false);

  /// Caller's n x k matrix -> a level's interleaved buffer in its internal numbering, and back.
  void load(const Level& L, Buffer& dst, const ConstMatrixRef& src);
  void store(const Level& L, const Buffer& src, MatrixRef dst);
};

}  // namespace mcf::multigrid_detail
