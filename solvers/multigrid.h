#pragma once
// Geometric multigrid on a given hierarchy (docs/octree-multigrid.md; Chuang & Kazhdan 2011,
// Section 5): Galerkin coarse operators A_l = P_lᵀ A_{l+1} P_l, V- or W-cycles, colour-parallel
// Gauss-Seidel smoothing, a direct solve on the coarsest level (SimplicialLDLT's factor, whose
// substitutions solvers/interleaved_ldlt.h runs for four columns at once).
//
// Determinism: every parallel kernel is a gather (each output entry is computed by exactly one
// task, in a fixed order), and norms use a deterministic reduction, so results are bitwise
// identical for any number of TBB threads.
//
// Files: the options (solvers/multigrid_options.h); the solver's state, one per solver
// (solvers/multigrid_state.h), set up by solvers/multigrid_setup.cpp (levels, internal numbering,
// Galerkin operators, coarsest factorization) and cycled by solvers/multigrid_cycle.cpp (V/W
// recursion, residual, transfers, coarsest solve); the smoother's kernels and sweeps
// (solvers/smoother.h), the Galerkin products (solvers/galerkin.h) and the internal numbering
// (solvers/level_ordering.h).
//
// Smoother ordering: a coloured level is cut into relaxation blocks of consecutive tiles (below),
// each at least as wide as the level's farthest coupling, so only neighbouring blocks couple. A
// forward sweep (pre-smoothing) relaxes the even blocks, in parallel, then the odd blocks; inside a
// block colours 0..7 one after the other (functions of one colour never couple, so their order
// does not matter). A reverse sweep (post-smoothing) is the exact reverse: odd blocks, then even
// blocks, colours 7..0. A level without a valid colouring (the surface hierarchy's coarse levels,
// whose Galerkin patterns need more than eight colours) is cut into blocks of consecutive rows
// instead, each at least as long as the level's farthest coupling in rows, and relaxed the same
// way, each block in row order (reverse: rows descending, odd blocks first). On a level numbered
// with a small bandwidth (the hat basis's Cuthill–McKee order, which the coarse levels inherit)
// that is nearly the lexicographic ordering, so it smooths as well as a serial sweep (the same
// contraction to three digits on the armadillo), and it runs in parallel; a level whose couplings
// reach across half of it has at most two blocks and is plain 0..n-1, reverse n-1..0. Every
// sweep is thus one fixed serial Gauss-Seidel ordering whatever the thread count, and with
// pre_smooth == post_smooth the cycle, started from zero, is a symmetric operator (precondition()).
// Why blocks and not one pass per colour over the whole level: a colour pass reads the iterates of
// all its rows' neighbours, i.e. nearly the whole iterate, eight times per sweep, and at depth 9
// that is more than the last-level cache holds; a block's rows and iterates stay in cache through
// its eight colours.
//
// Smoother matrix: the sweeps read each level's off-diagonal entries with 16-bit column offsets,
// in single precision on coarse levels, coloured or not (6 bytes an entry instead of 12), and in
// double precision on a coloured finest level (10 bytes; the values are the finest matrix's own,
// so the largest matrix is stored once): the sweeps stream the matrix ten times per level visit
// and are bound by its bytes.
// Coarse-level sweeps only shape a correction of the finest level's residual, which the
// residual, the transfers and the coarse operators keep exact, so the cycle converges to the
// solution of A x = b; a rounded finest-level matrix would not (solvers/smoother.h, SmootherRows).
// A level whose couplings lie farther apart than 16 bits reach keeps CSC sweeps. With
// MultigridOptions::mixed_precision the finest level's sweeps read single precision too, and
// solve() runs every cycle on the correction of a double-precision residual, so the finest sweeps
// only shape a correction as well.
//
// Internal numbering: every coloured level is stored in tiles of `tile_size` consecutive indices,
// colour-major inside each tile, so a colour pass streams contiguous segments of rows; the
// permutation is applied when right-hand sides and solutions are copied in and out, and to the
// finest matrix's values in set_matrix (block copies per column; set_matrix_sum writes a M + b K
// entry by entry in the same walk). The finest level of a hierarchy stores each column's diagonal
// last, so a sweep reads a row's off-diagonal entries as one run of the matrix itself. Only the
// order in which a row's terms are added differs from the caller's numbering (the finest level's
// sweeps add them in the caller's order, its residual too but for the diagonal's term, which it
// adds last; coarse levels add in internal order); level_matrix() converts back. A level whose
// given colouring is invalid keeps the internal order and is relaxed in blocks of rows of it.
//
// Layout and cost: right-hand sides are interleaved (row-major n x k, the row padded to a multiple
// of 4 columns) in preallocated per-level buffers; every kernel relaxes four columns of a row as
// one vector (the flows' x, y, z and a zero column). Per cycle on level l: pre + post sweeps, one
// residual, restriction b_c = Pᵀ r (gather over P's columns), prolongation x += P x_c (gather over
// the columns of the stored Pᵀ). The Galerkin pattern of Pᵀ (A_{l+1} P) is built once
// (symbolic_builds()); later set_matrix calls only recompute values: per coarse column J, v =
// A_{l+1} P e_J, then the upper entries (I <= J) as dot products P e_I · v, mirrored, so A_l is
// exactly symmetric and A P is never stored. From the second product on a pattern, v lives in a
// buffer of the column's few dozen fine rows, numbered once (solvers/galerkin.h, GalerkinPlan);
// before it, or where that plan would outgrow A, in a thread-local dense accumulator of the fine
// level's size. Measured numbers:
// docs/benchmarks.md (the micro-benchmarks BM_Rebuilt_Cycle, BM_Rebuilt_Sweep, BM_Floor_*).

#include "solvers/linear_solver.h"
#include "solvers/multigrid_options.h"

#include <cstdint>
#include <memory>
#include <vector>

namespace mcf {

/// The cycle's kernels one by one (MultigridSolver::run_kernel), for benchmarks that time a phase
/// against its floor (solvers/phase_floor.h).
enum class MultigridKernel {
  forward_sweep,  ///< one pre-smoothing sweep on level l
  reverse_sweep,  ///< one post-smoothing sweep on level l
  residual,       ///< r = b - A x on level l
  restriction,    ///< b_{l-1} = Pᵀ r_l
  prolongation,   ///< x_l += P x_{l-1}
  coarsest_solve  ///< the direct solve on level 0
};

class MultigridSolver : public LinearSolver {
 public:
  /// Consecutive function indices per tile of a coloured level's internal numbering.
  static constexpr int tile_size = 1024;

  explicit MultigridSolver(MultigridOptions options = {});
  ~MultigridSolver() override;
  MultigridSolver(const MultigridSolver&) = delete;
  MultigridSolver& operator=(const MultigridSolver&) = delete;
  MultigridSolver(MultigridSolver&&) noexcept;
  MultigridSolver& operator=(MultigridSolver&&) noexcept;

  std::string name() const override;

  /// A is the finest level's matrix. The hierarchy (prolongations coarsest first) is copied.
  /// When the patterns of A and of the prolongations (and the prolongation values) are those
  /// of the previous call (compared, or vouched for by hierarchy.pattern_key), only the
  /// numerical values of the coarse operators are recomputed (in parallel over coarse columns)
  /// and the coarsest factorization is refreshed numerically.
  /// An empty hierarchy gives a single level: the solve is then a direct solve.
  SolveReport set_matrix(const SparseMatrix& A, HierarchyView hierarchy = {}) override;

  /// set_matrix(a M + b K [+ s S]), bitwise, without the sum being stored anywhere but in this
  /// solver's finest level: when the pattern is unchanged, the sum is written straight into the
  /// permuted finest matrix (one pass over the terms instead of forming the sum and copying it);
  /// a new pattern is set up from M's, and the sum then written the same way.
  SolveReport set_matrix_sum(const MatrixSum& sum, HierarchyView hierarchy = {}) override;
  using LinearSolver::set_matrix_sum;

  /// z = one cycle applied to r from z = 0 (a symmetric operator when pre_smooth ==
  /// post_smooth); meant as a preconditioner for PCG. z is resized as needed.
  void precondition(const Eigen::MatrixXd& r, Eigen::MatrixXd& z);

  const MultigridOptions& options() const { return options_; }
  void set_options(const MultigridOptions& options) { options_ = options; }

  // --- introspection (tests, benchmarks) ---
  int levels() const;  ///< 0 before set_matrix
  /// Level l's operator (l = 0 coarsest, levels()-1 finest) in the caller's numbering (a copy).
  SparseMatrix level_matrix(int l) const;
  /// The finest level's operator in the caller's numbering, as level_matrix(levels() - 1) gives
  /// it, kept by the solver: laid out once per pattern, its values refreshed after set_matrix
  /// (what the stall fallback hands to CG and the factorization, step after step, without
  /// allocating). Valid until the next set_matrix.
  const SparseMatrix& finest_matrix() const;
  bool level_is_coloured(int l) const;  ///< false: relaxed in blocks of rows, no colours
  /// Whether level l's sweeps read the compact rows: 16-bit offsets, single-precision values on
  /// coarse levels, double on the finest (header, "Smoother matrix").
  bool level_has_compact_smoother(int l) const;
  /// Level l's functions (caller's numbering) in the order one sweep relaxes them: the serial
  /// Gauss-Seidel ordering the parallel sweep equals (header, "Smoother ordering").
  std::vector<int> relaxation_order(int l, bool reverse = false) const;
  /// Level l's relaxation block of each function (caller's numbering; all 0 on a serial level).
  /// Blocks of one parity are relaxed in parallel, which is exact only because functions of
  /// blocks q and q' with |q - q'| >= 2 never couple.
  std::vector<int> relaxation_blocks(int l) const;
  std::int64_t symbolic_builds() const;  ///< how often the Galerkin pattern was built
  std::int64_t numeric_builds() const;   ///< how often coarse values were computed
  /// How many set_matrix calls kept the coarse operators of an earlier call (galerkin_refresh).
  std::int64_t lagged_refreshes() const;
  /// How many Galerkin products of one term on one level galerkin_by_term has computed (a refresh
  /// of a sum of two terms on L levels computes 2 (L - 1) when both changed, L - 1 when one did).
  std::int64_t term_products() const;
  /// How often set_matrix compared the given pattern with the stored one (skipped when the
  /// caller's pattern_key vouches for it).
  std::int64_t pattern_comparisons() const;
  /// Per level (coarsest first), summed over all cycles of solve() and precondition() since the
  /// levels were built (or since reset_level_work()); cleared when a new pattern is set up.
  std::vector<MultigridLevelWork> level_work() const;
  void reset_level_work();

  /// Entries a sweep on level l reads (its off-diagonal entries) and the bytes of each (offset
  /// and value: 6 on a coarse level's compact rows, 10 on the finest's, 12 on CSC sweeps).
  std::int64_t level_sweep_entries(int l) const;
  int level_sweep_entry_bytes(int l) const;
  /// Entries of the coarsest level's LDLᵀ factor (L's, the unit diagonal included; 0 when the
  /// pseudo-inverse serves: then n² entries are read).
  std::int64_t coarsest_factor_nonzeros() const;
  /// Runs one kernel of the cycle on level l's own buffers, sized for `columns` right-hand
  /// sides (l >= 1 for restriction and prolongation, l = 0 for the coarsest solve). The buffers
  /// hold what the last call left (zeros at first): the kernels' work does not depend on it.
  void run_kernel(MultigridKernel kernel, int l, int columns);

  /// `sweeps` Gauss-Seidel sweeps on level l for A_l X = B, forward or reverse in the order
  /// relaxation_order(l, reverse) lists (header, "Smoother ordering"). X is updated in place.
  void gauss_seidel(int l, const Eigen::MatrixXd& B, Eigen::MatrixXd& X, int sweeps,
                    bool reverse = false);

 protected:
  /// Runs cycles from the warm start X (solve(): zero if a resizable X has another shape).
  /// residuals[c] = max over columns of ||B - A X|| / ||B|| after cycle c.
  SolveReport solve_in_place(const ConstMatrixRef& B, MatrixRef X) override;

 private:
  struct Impl;
  /// Both set_matrix entries: the finest values are A's, or the sum's when one is given (A = its
  /// M).
  SolveReport set_levels(const SparseRef& A, const MatrixSum* sum, HierarchyView hierarchy);
  MultigridOptions options_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mcf
