#include "solvers/multigrid.h"

#include "core/vec4.h"
#include "solvers/csc_view.h"
#include "solvers/galerkin.h"
#include "solvers/interleaved_ldlt.h"
#include "solvers/level_ordering.h"
#include "solvers/smoother.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <new>
#include <stdexcept>
#include <string>
#include <utility>

namespace mcf {

static_assert(multigrid_detail::kTile == MultigridSolver::tile_size,
              "solvers/level_ordering.h tiles levels as the solver stores them");

const char* to_string(MultigridCycle c) {
  return c == MultigridCycle::V ? "V" : "W";
}

// The solver's parts: the smoother (solvers/smoother.h), the Galerkin product
// (solvers/galerkin.h) and the internal numbering (solvers/level_ordering.h).
using namespace multigrid_detail;

namespace {

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

// The cycle's other kernels, on the interleaved buffers of solvers/smoother.h.

/// r = b - A x (rows [begin, end)), columns o..o+3.
MCF_KERNEL_INLINE void residual_rows(const Csc& A, const double* b, const double* x, double* r,
                                     std::size_t s, int o, int begin, int end) {
  for (int i = begin; i < end; ++i) {
    const std::size_t ii = std::size_t(i) * s + o;
    v4 acc0 = load4(b + ii), acc1 = splat(0.0);
    gather_sub(A, x, s, o, A.outer[i], A.outer[i + 1], acc0, acc1);
    store4(r + ii, acc0 + acc1);
  }
}

/// y = Mᵀ v (or y += Mᵀ v when Add) on output rows [begin, end) = columns of M (gather along
/// columns, so parallel output ranges never write the same entry), columns o..o+3.
template <bool Add>
MCF_KERNEL_INLINE void transpose_rows(const Csc& M, const double* v, double* y, std::size_t s,
                                      int o, int begin, int end) {
  for (int J = begin; J < end; ++J) {
    v4 acc0 = splat(0.0), acc1 = splat(0.0);
    gather_sub(M, v, s, o, M.outer[J], M.outer[J + 1], acc0, acc1);
    double* yJ = y + std::size_t(J) * s + o;
    const v4 sum = -(acc0 + acc1);
    store4(yJ, Add ? load4(yJ) + sum : sum);
  }
}

}  // namespace

// ------------------------------------------------------------------------------------------

struct MultigridSolver::Impl {
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

  void ensure_buffers(int cols) {
    if (cols == k) return;
    k = cols;
    s = (std::size_t(k) + 3) / 4 * 4;
    for (auto& L : levels) {
      const std::size_t sz = std::size_t(L.n()) * s;
      L.x.assign(sz, 0.0);
      L.b.assign(sz, 0.0);
      L.r.assign(sz, 0.0);
    }
    coarse_rhs.resize(levels.front().n(), k);
    coarse_sol.resize(levels.front().n(), k);
  }

  void symbolic(const SparseRef& A, const std::vector<SparseMatrix>& P,
                const std::vector<std::vector<std::uint8_t>>* given_colours, bool single) {
    fine_single = single;
    finest_from.clear();
    const std::size_t nl = P.size() + 1;
    levels.clear();
    levels.resize(nl);
    colours.clear();
    if (given_colours != nullptr) colours = *given_colours;
    // A single level is solved directly (never smoothed): it keeps the caller's numbering.
    for (std::size_t l = 0; nl > 1 && l < nl; ++l) {
      const int n = l + 1 < nl ? int(P[l].cols()) : int(A.rows());
      number_by_colour(levels[l], n, l < colours.size() ? &colours[l] : nullptr);
    }
    // The finest matrix keeps each column's entries in the caller's order, except its diagonal,
    // which it stores last (diagonal_last: the smoother then reads a row's off-diagonal entries
    // as one run of the matrix itself). Later value updates are three block copies per column
    // (set_fine_values); the sweeps add a row's terms in the caller's order, the residual adds
    // the diagonal's term last.
    Level& F = levels.back();
    F.A = permuted(A, F.inv, F.perm, false);
    F.diag_rank.clear();
    if (nl > 1) F.diag_rank = diagonal_last(F.A);
    for (std::size_t l = 0; l + 1 < nl; ++l) {
      SparseMatrix given = P[l];
      given.makeCompressed();
      levels[l].P = permuted(given, levels[l + 1].inv, levels[l].perm, true);
      levels[l].PT = SparseMatrix(levels[l].P.transpose());
      levels[l].PT.makeCompressed();
    }
    for (std::size_t l = nl - 1; l-- > 0;) {
      Level& C = levels[l];
      C.A = symbolic_product(C.PT, symbolic_product(levels[l + 1].A, C.P));  // pattern of Pᵀ (A P)
      // Positions of transposed entries, to symmetrize the computed values exactly.
      C.transpose_pos = transpose_positions(C.A);
    }
    for (std::size_t l = 0; l < nl; ++l) {
      Level& L = levels[l];
      check_colouring(L, L.A, l < colours.size() ? &colours[l] : nullptr);
      L.diag_pos = diagonal_positions(L.A);
      find_blocks(L, L.A);
      // Coarse levels, coloured or not, sweep on compact single-precision rows; a coloured
      // finest level on compact rows aligned with its own values unless its sweeps read single
      // precision; a finest level without colours on the double-precision matrix.
      const bool finest = l + 1 == nl;
      L.smoother = !finest      ? smoother_pattern(L.A, L.diag_pos, false)
                   : L.coloured ? smoother_pattern(L.A, L.diag_pos, !fine_single)
                                : SmootherRows{};
    }
    k = 0;
    work.assign(nl, MultigridLevelWork{});
    ++symbolic_builds;
  }

  /// Walks the finest matrix's stored entries column by column: put(p, q, out) writes the
  /// caller's entries [p, q) (positions in G, the caller's numbering) at `out` (in `val`, an array
  /// on the finest pattern) and returns the end of what it wrote. The diagonal goes last
  /// (diagonal_last).
  template <class Put>
  void walk_fine(const Csc& G, double* val, const Put& put) {
    Level& F = levels.back();
    const int* outer = F.A.outerIndexPtr();
    for_rows(F.n(), [&](int rb, int re) {
      for (int r = rb; r < re; ++r) {
        const int j = old_index(F.perm, r);
        const int g0 = G.outer[j], g1 = G.outer[j + 1];
        const int k = F.diag_rank.empty() ? -1 : F.diag_rank[std::size_t(r)];
        double* out = val + outer[r];
        if (k < 0 || k >= g1 - g0) {
          put(g0, g1, out);
          continue;
        }
        // The diagonal last (diagonal_last): the entries before it, after it, then it.
        out = put(g0, g0 + k, out);
        out = put(g0 + k + 1, g1, out);
        put(g0 + k, g0 + k + 1, out);
      }
    });
  }

  /// New values of the finest matrix (same pattern as the stored one, in the caller's numbering):
  /// A's, or the sum's entry by entry when one is given (its terms on A's pattern, A its M;
  /// sum_entry, so bitwise what sum_on_pattern would have handed to set_matrix).
  void set_fine_values(const SparseRef& A, const MatrixSum* sum) {
    const Csc G(A);
    const double* kv = sum ? sum->K.valuePtr() : nullptr;
    const double* sv = sum && sum->S ? sum->S->valuePtr() : nullptr;
    const double a = sum ? sum->a : 1.0, b = sum ? sum->b : 0.0, s = sum ? sum->s : 0.0;
    // Caller's entries [p, q) of column j to out: copied, or summed with the other terms'.
    walk_fine(G, levels.back().A.valuePtr(), [&](int p, int q, double* out) {
      if (!kv) return std::copy(G.val + p, G.val + q, out);
      if (sv)
        for (; p < q; ++p) *out++ = sum_entry(a, G.val[p], b, kv[p], s, sv[p]);
      else
        for (; p < q; ++p) *out++ = sum_entry(a, G.val[p], b, kv[p]);
      return out;
    });
  }

  /// galerkin_by_term: the sum's terms into the finest level's `terms`, and which of them changed
  /// (term_changed; bitwise comparison with the kept copy). `fresh`: the levels were just built or
  /// held another number of terms; every level's terms are then sized and all count as changed.
  void set_fine_terms(const MatrixSum& sum, bool fresh) {
    const SparseRef* term[3] = {&sum.M, &sum.K, sum.S ? &*sum.S : nullptr};
    const int count = sum.S ? 3 : 2;
    if (fresh || term_count != count) {
      for (auto& L : levels)
        L.terms.assign(std::size_t(count), std::vector<double>(std::size_t(L.A.nonZeros()), 0.0));
      term_count = count;
      term_changed.assign(std::size_t(count), 1);
    } else {
      term_changed.assign(std::size_t(count), 0);
    }
    for (int t = 0; t < count; ++t) {
      const Csc G(*term[t]);
      std::atomic<bool> changed{false};
      walk_fine(G, levels.back().terms[std::size_t(t)].data(), [&](int p, int q, double* out) {
        bool differs = false;
        for (; p < q; ++p, ++out) {
          differs |= std::bit_cast<std::uint64_t>(*out) != std::bit_cast<std::uint64_t>(G.val[p]);
          *out = G.val[p];
        }
        if (differs) changed.store(true, std::memory_order_relaxed);
        return out;
      });
      if (changed.load()) term_changed[std::size_t(t)] = 1;
    }
  }

  /// The Galerkin plan of coarse level l (solvers/galerkin.h). Laying it out costs about two
  /// products, which a pattern used once (the rebuilt octree's, new every step) would not earn
  /// back: it is built when the level's product is computed a second time on its pattern, or at
  /// once when the caller vouches for its pattern with a key (it owns a fixed pattern and will
  /// set it again), so that the flow's second step is a steady one.
  const GalerkinPlan* plan_for(std::size_t l) {
    Level& C = levels[l];
    if (++C.galerkin_calls == (pattern_key != 0 ? 1 : 2))
      C.plan = galerkin_plan(Csc(levels[l + 1].A), C.P, C.A, C.inv);
    return &C.plan;
  }

  /// Drops the kept terms (a call without a sum, or without the option).
  void drop_terms() {
    term_count = 0;
    term_changed.clear();
    for (auto& L : levels) L.terms.clear();
  }

  /// galerkin_by_term: coarse level l's terms that changed, then its matrix as their sum.
  void coarse_by_term(std::size_t l, const MatrixSum& sum) {
    Level& C = levels[l];
    const Level& F = levels[l + 1];
    for (int t = 0; t < term_count; ++t) {
      if (!term_changed[std::size_t(t)]) continue;
      Csc A(F.A);
      A.val = F.terms[std::size_t(t)].data();
      galerkin_values(A, C.P, C.A, C.terms[std::size_t(t)].data(), C.transpose_pos, C.inv, C.spa,
                      plan_for(l));
      ++term_products;
    }
    const double* mv = C.terms[0].data();
    const double* kv = C.terms[1].data();
    const double* sv = term_count > 2 ? C.terms[2].data() : nullptr;
    double* val = C.A.valuePtr();
    for_rows(int(C.A.nonZeros()), [&](int p, int q) {
      if (sv)
        for (; p < q; ++p) val[p] = sum_entry(sum.a, mv[p], sum.b, kv[p], sum.s, sv[p]);
      else
        for (; p < q; ++p) val[p] = sum_entry(sum.a, mv[p], sum.b, kv[p]);
    });
  }

  /// Numerical values of all levels from the finest level's values (already in place).
  /// Returns false when a diagonal entry is negative or not finite.
  /// With `by_term` (the sum's terms set by set_fine_terms), coarse levels are refreshed by
  /// term (coarse_by_term).
  /// With `coarse` false (a lagged refresh), only the finest level's diagonal and smoother.
  bool numeric(const MatrixSum* by_term, bool coarse = true) {
    for (std::size_t l = levels.size() - 1; coarse && l-- > 0;) {
      Level& C = levels[l];
      if (by_term)
        coarse_by_term(l, *by_term);
      else
        galerkin_values(Csc(levels[l + 1].A), C.P, C.A, C.A.valuePtr(), C.transpose_pos, C.inv,
                        C.spa, plan_for(l));
    }
    bool ok = true;
    for (std::size_t l = coarse ? 0 : levels.size() - 1; l < levels.size(); ++l) {
      Level& L = levels[l];
      const Csc A(L.A);
      L.inv_diag.resize(std::size_t(L.n()));  // every entry written below
      double* inv = L.inv_diag.data();
      const int* diag_pos = L.diag_pos.data();
      std::atomic<bool> bad{false};
      for_rows(L.n(), [&](int b, int e) {
        bool unsound = false;
        for (int i = b; i < e; ++i) {
          const int p = diag_pos[i];
          const double d = p >= 0 ? A.val[p] : 0.0;
          unsound |= !(d >= 0.0) || !std::isfinite(d);
          inv[i] = d > 0.0 ? 1.0 / d : 0.0;
        }
        if (unsound) bad.store(true, std::memory_order_relaxed);
      });
      if (bad.load()) ok = false;
      smoother_values(L.smoother, L.A, L.diag_pos);
    }
    if (coarse) ++numeric_builds;
    return ok;
  }

  // ---- cycle ----

  /// One Gauss-Seidel sweep on level l (solvers/smoother.h, gauss_seidel_sweep).
  void sweep(int l, bool reverse) {
    Level& L = levels[std::size_t(l)];
    gauss_seidel_sweep(L, Csc(L.A), L.smoother, L.diag_pos.data(), L.inv_diag.data(), L.b.data(),
                       L.x.data(), s, reverse);
  }

  void residual(int l) {
    Level& L = levels[std::size_t(l)];
    const Csc A(L.A);
    for (int o = 0; o < int(s); o += 4)
      for_rows(A.cols, [&](int b, int e) {
        residual_rows(A, L.b.data(), L.x.data(), L.r.data(), s, o, b, e);
      });
  }

  // Whether the LDLᵀ factor of the coarsest matrix is fit to solve with: it succeeded and no
  // pivot is below 1e-10 of its row's diagonal entry (a dependent function leaves a pivot of
  // rounding size, whose inverse would fill the solution with a huge null-space component).
  bool coarsest_factor_is_sound() const {
    if (ldlt.info() != Eigen::Success) return false;
    const Eigen::VectorXd D = ldlt.vectorD();
    const SparseMatrix& A = levels.front().A;
    const auto& P = ldlt.permutationP().indices();  // (P A Pᵀ)(P[i], P[i]) = A(i, i)
    for (Eigen::Index i = 0; i < A.rows(); ++i) {
      const double d = D[P[i]], a = A.coeff(i, i);
      if (!(d > 1e-10 * a) || !(a > 0)) return false;
    }
    return true;
  }

  // The coarsest matrix's generalized inverse, from the eigen-decomposition of its Jacobi
  // scaling Â = S⁻¹AS⁻¹ (S² = diag A, so a function that barely meets the surface is not taken
  // for a null direction): A⁺ = S⁻¹ V Λ⁺ Vᵀ S⁻¹, with eigenvalues below 1e-11 λ_max taken as 0.
  // For a consistent right-hand side (the restriction of a fine residual of a consistent
  // system) it gives the solution without a null-space component. Returns why it cannot be used
  // (a negative eigenvalue: the matrix is indefinite; too large to decompose), else "" and the
  // null space's dimension in `null_dimension`.
  std::string coarsest_pseudo_inverse(int& null_dimension) {
    const SparseMatrix& A = levels.front().A;
    const Eigen::Index n = A.rows();
    if (n > 4096)
      return "coarsest-level factorization failed (" + std::to_string(n) +
             " functions: too many for its dense pseudo-inverse)";
    Eigen::MatrixXd dense = Eigen::MatrixXd(A);
    Eigen::VectorXd scale(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      // A zero diagonal entry of a semi-definite matrix has a zero row: a coarse function all of
      // whose finer functions are held (an open surface's locked boundary); scale 0 leaves it out.
      if (dense(i, i) == 0 && dense.row(i).isZero(0)) {
        scale[i] = 0;
        continue;
      }
      if (!(dense(i, i) > 0)) return "coarsest-level matrix is not positive definite";
      scale[i] = 1.0 / std::sqrt(dense(i, i));
    }
    dense = scale.asDiagonal() * dense * scale.asDiagonal();
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(dense);
    if (eig.info() != Eigen::Success) return "coarsest-level eigen-decomposition failed";
    const Eigen::VectorXd& lambda = eig.eigenvalues();  // ascending
    const double top = lambda[n - 1], floor = 1e-11 * top;
    if (!(lambda[0] >= -floor))
      return "coarsest-level matrix is not positive definite (eigenvalue " +
             std::to_string(lambda[0] / top) + " of the largest)";
    Eigen::VectorXd inverse(n);
    null_dimension = 0;
    for (Eigen::Index i = 0; i < n; ++i) {
      inverse[i] = lambda[i] > floor ? 1.0 / lambda[i] : 0.0;
      null_dimension += lambda[i] > floor ? 0 : 1;
    }
    const Eigen::MatrixXd W = scale.asDiagonal() * eig.eigenvectors();
    coarse_pinv = W * inverse.asDiagonal() * W.transpose();
    return {};
  }

  void coarse_solve() {
    Level& L = levels.front();
    const int n = L.n();
    if (coarse_pinv.size() == 0) {
      // The padding columns of b are zero, so those of x come out zero, as everywhere else.
      solve_interleaved(coarse_factor, L.b.data(), L.x.data(), s, coarse_work);
      return;
    }
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < k; ++c) coarse_rhs(i, c) = L.b[std::size_t(i) * s + std::size_t(c)];
    coarse_sol.noalias() = coarse_pinv * coarse_rhs;
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < k; ++c) L.x[std::size_t(i) * s + std::size_t(c)] = coarse_sol(i, c);
  }

  // Two clock reads per level visit (a W-cycle at depth 9 makes 384): noise next to the sweeps.
  using Clock = std::chrono::steady_clock;
  static double since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
  }

  /// Restriction b_C = Pᵀ r_F from level l to l - 1 (gather over the columns of P), and the
  /// coarse level's start x_C = 0, in the same pass over its rows (in parallel, instead of a
  /// serial fill of its own).
  void restrict_residual(int l) {
    const Level& F = levels[std::size_t(l)];
    Level& C = levels[std::size_t(l) - 1];
    const Csc P(C.P);
    for (int o = 0; o < int(s); o += 4)
      for_rows(P.cols, [&](int b, int e) {
        transpose_rows<false>(P, F.r.data(), C.b.data(), s, o, b, e);
        for (int J = b; J < e; ++J) store4(C.x.data() + std::size_t(J) * s + o, splat(0.0));
      });
  }

  /// x = 0 on level L, in parallel over its rows.
  void zero_iterate(Level& L) {
    double* x = L.x.data();
    for_rows(L.n(),
             [&](int b, int e) { std::fill(x + std::size_t(b) * s, x + std::size_t(e) * s, 0.0); });
  }

  /// Prolongation x_F += P x_C from level l - 1 to l (gather over the columns of Pᵀ = rows of P).
  void prolongate(int l) {
    Level& F = levels[std::size_t(l)];
    const Level& C = levels[std::size_t(l) - 1];
    const Csc PT(C.PT);
    for (int o = 0; o < int(s); o += 4)
      for_rows(PT.cols,
               [&](int b, int e) { transpose_rows<true>(PT, C.x.data(), F.x.data(), s, o, b, e); });
  }

  void cycle(int l, const MultigridOptions& opt) {
    const auto t0 = Clock::now();
    MultigridLevelWork& w = work[std::size_t(l)];
    ++w.visits;
    if (l == 0) {
      coarse_solve();
      w.seconds += since(t0);
      return;
    }
    for (int i = 0; i < opt.pre_smooth; ++i) sweep(l, false);
    residual(l);
    restrict_residual(l);  // and C.x = 0
    // γ = 2 for W; an exact coarsest solve is never repeated (it would change nothing).
    const int gamma = (opt.cycle == MultigridCycle::W && l - 1 > 0) ? 2 : 1;
    const auto tc = Clock::now();
    for (int g = 0; g < gamma; ++g) cycle(l - 1, opt);
    const double coarser = since(tc);  // the recursion's time, not this level's own
    prolongate(l);
    for (int i = 0; i < opt.post_smooth; ++i) sweep(l, true);
    w.seconds += since(t0) - coarser;
  }

  /// Runs one cycle on the correction of the finest level's iterate (mixed_precision): from
  /// r = b - A x (computed here unless `have_r`: the finest level's r holds it already), the
  /// cycle solves A e ≈ r from e = 0, and x += e.
  void correction_cycle(const MultigridOptions& opt, bool have_r) {
    const int top = int(levels.size()) - 1;
    Level& F = levels.back();
    if (!have_r) residual(top);
    if (F.saved_b.size() != F.b.size()) F.saved_b.assign(F.b.size(), 0.0);
    if (F.saved_x.size() != F.x.size()) F.saved_x.assign(F.x.size(), 0.0);
    std::swap(F.b, F.saved_b);  // b kept
    std::swap(F.b, F.r);        // the cycle's right-hand side: the residual
    std::swap(F.x, F.saved_x);  // x kept
    zero_iterate(F);
    cycle(top, opt);
    double* x = F.x.data();
    const double* x0 = F.saved_x.data();
    for_rows(int(F.x.size()), [&](int b, int e) {
      for (int i = b; i < e; ++i) x[i] = x0[i] + x[i];
    });
    std::swap(F.b, F.saved_b);  // b back
  }

  /// max over columns of ||b - A x|| / ||b|| on the finest level (deterministic reduction). With
  /// `keep`, the residual b - A x is also stored in the finest level's r (what residual() would
  /// write, bitwise: the same terms in the same order).
  double relative_residual(const Eigen::VectorXd& bnorm, bool keep = false) {
    Level& L = levels.back();
    const Csc A(L.A);
    std::vector<double> rn(s, 0.0);
    for (int o = 0; o < int(s); o += 4) {
      struct Acc {
        v4 v = {0.0, 0.0, 0.0, 0.0};
      };
      const Acc sum = tbb::parallel_deterministic_reduce(
          tbb::blocked_range<int>(0, A.cols, 4096), Acc{},
          [&](const tbb::blocked_range<int>& r, Acc acc) {
            for (int i = r.begin(); i < r.end(); ++i) {
              v4 res0 = load4(L.b.data() + std::size_t(i) * s + o), res1 = splat(0.0);
              gather_sub(A, L.x.data(), s, o, A.outer[i], A.outer[i + 1], res0, res1);
              const v4 res = res0 + res1;
              if (keep) store4(L.r.data() + std::size_t(i) * s + o, res);
              acc.v += res * res;
            }
            return acc;
          },
          [](Acc a, const Acc& b) {
            a.v += b.v;
            return a;
          });
      for (int c = 0; c < 4; ++c) rn[std::size_t(o + c)] = sum.v[c];
    }
    double worst = 0.0;
    for (int c = 0; c < k; ++c) {
      const double r = std::sqrt(rn[std::size_t(c)]);
      const double rel = bnorm[c] > 0.0 ? r / bnorm[c] : r;
      if (std::isnan(rel)) return rel;
      worst = std::max(worst, rel);
    }
    return worst;
  }

  /// Caller's n x k matrix -> a level's interleaved buffer in its internal numbering, and back.
  void load(const Level& L, Buffer& dst, const ConstMatrixRef& src) {
    for_rows(int(src.rows()), [&](int b, int e) {
      for (int r = b; r < e; ++r) {
        const int i = old_index(L.perm, r);
        for (int c = 0; c < k; ++c) dst[std::size_t(r) * s + std::size_t(c)] = src(i, c);
      }
    });
  }
  void store(const Level& L, const Buffer& src, MatrixRef dst) {
    for_rows(int(dst.rows()), [&](int b, int e) {
      for (int r = b; r < e; ++r) {
        const int i = old_index(L.perm, r);
        for (int c = 0; c < k; ++c) dst(i, c) = src[std::size_t(r) * s + std::size_t(c)];
      }
    });
  }
};

// ------------------------------------------------------------------------------------------

MultigridSolver::MultigridSolver(MultigridOptions options)
    : options_(options), impl_(std::make_unique<Impl>()) {}
MultigridSolver::~MultigridSolver() = default;
MultigridSolver::MultigridSolver(MultigridSolver&&) noexcept = default;
MultigridSolver& MultigridSolver::operator=(MultigridSolver&&) noexcept = default;

std::string MultigridSolver::name() const {
  return std::string("multigrid-") + to_string(options_.cycle);
}

int MultigridSolver::levels() const {
  return impl_->ready ? int(impl_->levels.size()) : 0;
}
SparseMatrix MultigridSolver::level_matrix(int l) const {
  const auto& L = impl_->levels.at(std::size_t(l));
  return permuted(L.A, L.perm, L.inv, true);  // back to the caller's numbering
}
const SparseMatrix& MultigridSolver::finest_matrix() const {
  Impl& m = *impl_;
  if (m.levels.empty()) throw std::logic_error("MultigridSolver::finest_matrix before set_matrix");
  const auto& L = m.levels.back();
  if (m.finest_from.empty()) {
    // Each entry's position as its value, moved as level_matrix moves the values: exact in a
    // double up to 2^53 entries.
    SparseMatrix positions = L.A;
    for (Eigen::Index p = 0; p < positions.nonZeros(); ++p) positions.valuePtr()[p] = double(p);
    m.finest = permuted(positions, L.perm, L.inv, true);
    m.finest_from.resize(std::size_t(m.finest.nonZeros()));
    for (Eigen::Index p = 0; p < m.finest.nonZeros(); ++p)
      m.finest_from[std::size_t(p)] = int(m.finest.valuePtr()[p]);
    m.finest_call = -1;
  }
  if (m.finest_call != m.calls) {
    const double* from = L.A.valuePtr();
    double* to = m.finest.valuePtr();
    const int* where = m.finest_from.data();
    for_rows(int(m.finest.nonZeros()), [&](int b, int e) {
      for (int p = b; p < e; ++p) to[p] = from[where[p]];
    });
    m.finest_call = m.calls;
  }
  return m.finest;
}
bool MultigridSolver::level_is_coloured(int l) const {
  return impl_->levels.at(std::size_t(l)).coloured;
}
bool MultigridSolver::level_has_compact_smoother(int l) const {
  const auto& L = impl_->levels.at(std::size_t(l));
  return !L.smoother.empty();
}
std::vector<int> MultigridSolver::relaxation_blocks(int l) const {
  const auto& L = impl_->levels.at(std::size_t(l));
  std::vector<int> block(std::size_t(L.n()), 0);
  if (!L.coloured) {
    for (int q = 0; q < L.blocks(); ++q)
      for (int r = L.block_first(q); r < L.block_last(q); ++r)
        block[std::size_t(old_index(L.perm, r))] = q;
    return block;
  }
  // Block membership as the sweep itself walks it (for_block_segments), not re-derived here.
  for (int q = 0; q < L.blocks(); ++q)
    for_block_segments(L, q, false, [&](int r0, int r1) {
      for (int r = r0; r < r1; ++r) block[std::size_t(old_index(L.perm, r))] = q;
    });
  return block;
}
std::vector<int> MultigridSolver::relaxation_order(int l, bool reverse) const {
  const auto& L = impl_->levels.at(std::size_t(l));
  return multigrid_detail::relaxation_order(L, L.n(), reverse);
}
std::int64_t MultigridSolver::symbolic_builds() const {
  return impl_->symbolic_builds;
}
std::int64_t MultigridSolver::numeric_builds() const {
  return impl_->numeric_builds;
}

std::int64_t MultigridSolver::lagged_refreshes() const {
  return impl_->lagged_refreshes;
}
std::int64_t MultigridSolver::term_products() const {
  return impl_->term_products;
}
std::int64_t MultigridSolver::pattern_comparisons() const {
  return impl_->pattern_comparisons;
}
std::vector<MultigridLevelWork> MultigridSolver::level_work() const {
  return impl_->work;
}
void MultigridSolver::reset_level_work() {
  for (auto& w : impl_->work) w = MultigridLevelWork{};
}

SolveReport MultigridSolver::set_matrix(const SparseMatrix& A, HierarchyView hierarchy) {
  return set_levels(A, nullptr, hierarchy);
}

SolveReport MultigridSolver::set_matrix_sum(const MatrixSum& sum, HierarchyView hierarchy) {
  if (!summable(sum)) return LinearSolver::set_matrix_sum(sum, hierarchy);  // the general sum
  return set_levels(sum.M, &sum, hierarchy);
}

SolveReport MultigridSolver::set_levels(const SparseRef& A_in, const MatrixSum* sum,
                                        HierarchyView hierarchy) {
  SolveReport rep;
  Impl& m = *impl_;
  const bool was_ready = m.ready;
  m.ready = false;
  auto fail = [&](SolveStatus st, std::string msg) {
    rep.status = st;
    rep.message = std::move(msg);
    return rep;
  };
  if (A_in.rows() != A_in.cols() || A_in.rows() == 0)
    return fail(SolveStatus::failed, "matrix is not square or empty");
  // An uncompressed input is compressed into a copy (the kernels read the CSC arrays alone).
  SparseMatrix compressed;
  if (!A_in.isCompressed()) {
    compressed = A_in;
    compressed.makeCompressed();
  }
  const SparseRef A = A_in.isCompressed() ? A_in : SparseRef(compressed);

  static const std::vector<SparseMatrix> kNone;
  const std::vector<SparseMatrix>& P = hierarchy.empty() ? kNone : *hierarchy.prolongations;
  const auto* colours = hierarchy.colours;
  // Dimensions: P[l] maps level l to l+1; the last one maps onto A's level.
  Eigen::Index fine = A.rows();
  for (std::size_t l = P.size(); l-- > 0;) {
    if (P[l].rows() != fine || P[l].cols() <= 0)
      return fail(SolveStatus::failed,
                  "prolongation " + std::to_string(l) + " has wrong dimensions");
    fine = P[l].cols();
  }

  const std::uint64_t key = hierarchy.pattern_key;
  const bool vouched = key != 0 && key == m.pattern_key;
  m.pattern_key = 0;  // until this call has set up levels for the given pattern
  // The O(1) checks run even when vouched for: a wrong key must not make set_fine_values write
  // past the stored pattern.
  bool need_symbolic = m.levels.size() != P.size() + 1 || m.levels.back().n() != A.rows() ||
                       m.levels.back().A.nonZeros() != A.nonZeros();
  if (!need_symbolic && !vouched) {
    ++m.pattern_comparisons;
    const std::size_t nc = colours ? colours->size() : 0;
    need_symbolic = nc != m.colours.size() || (nc > 0 && *colours != m.colours);
    if (!need_symbolic) {
      const auto& F = m.levels.back();
      need_symbolic = !same_permuted(F.A, A, F.inv, F.perm, false, false, F.diag_rank);
    }
    for (std::size_t l = 0; !need_symbolic && l < P.size(); ++l)
      need_symbolic =
          !same_permuted(m.levels[l].P, P[l], m.levels[l + 1].inv, m.levels[l].perm, true, true);
  }
  // symbolic() copies A's values along with its pattern; a sum overwrites them.
  // A vouched-for pattern is still set up anew when the finest sweeps' precision changed.
  if (!need_symbolic && m.fine_single != options_.mixed_precision) need_symbolic = true;
  if (need_symbolic) m.symbolic(A, P, colours, options_.mixed_precision);
  if (!need_symbolic || sum) m.set_fine_values(A, sum);
  ++m.calls;
  const bool by_term = options_.galerkin_by_term && sum != nullptr && m.levels.size() > 1;
  if (by_term)
    m.set_fine_terms(*sum, need_symbolic);
  else
    m.drop_terms();
  m.pattern_key = key;
  // galerkin_refresh: keep the coarse operators of an earlier successful call on this pattern.
  // `ready` was true before this call exactly when that call succeeded (it is reset above).
  const bool lagged = !need_symbolic && !by_term && m.levels.size() > 1 && was_ready &&
                      options_.galerkin_refresh > 1 &&
                      m.calls_since_refresh + 1 < options_.galerkin_refresh;
  const bool diag_ok = m.numeric(by_term ? sum : nullptr, !lagged);
  if (lagged) {
    ++m.calls_since_refresh;
    ++m.lagged_refreshes;
  } else {
    m.calls_since_refresh = 0;
    if (need_symbolic) m.ldlt.analyzePattern(m.levels.front().A);
    m.ldlt.factorize(m.levels.front().A);
  }
  if (!diag_ok)
    return fail(SolveStatus::not_positive_definite, "negative or non-finite diagonal entry");
  if (!lagged) {
    // The coarse levels' notes, which a lagged call repeats with their operators.
    m.coarse_note.clear();
    m.coarse_pinv.resize(0, 0);
    if (m.coarsest_factor_is_sound())
      copy_factor(m.ldlt, m.coarse_factor);
    else {
      // The octree's functions on a flat face parallel to a grid plane (the cubical spiral, a
      // box) are linearly dependent on the surface: A is then only semi-definite, on every
      // level. Gauss–Seidel relaxes such a consistent system as it does a definite one (the
      // paper's solver never factors the fine matrix); the coarsest level needs a generalized
      // inverse.
      int null_dimension = 0;
      const std::string why = m.coarsest_pseudo_inverse(null_dimension);
      if (!why.empty()) return fail(SolveStatus::not_positive_definite, why);
      m.coarse_note = "coarsest level semi-definite (null space of dimension " +
                      std::to_string(null_dimension) + "): solved by its pseudo-inverse";
    }
    for (std::size_t l = 1; l < m.levels.size(); ++l)
      if (!m.levels[l].coloured)
        m.coarse_note += (m.coarse_note.empty() ? "" : "; ") + std::string("level ") +
                         std::to_string(l) + " has no valid colouring: relaxed in blocks of rows";
  }
  rep.message = m.coarse_note;
  m.ready = true;
  rep.iterations = 0;
  return rep;
}

SolveReport MultigridSolver::solve_in_place(const ConstMatrixRef& B, MatrixRef X) {
  SolveReport rep;
  Impl& m = *impl_;
  if (!m.ready) {
    rep.status = SolveStatus::failed;
    rep.message = "set_matrix was not called or failed";
    return rep;
  }
  const int n = m.levels.back().n();
  if (B.rows() != n) {
    rep.status = SolveStatus::failed;
    rep.message = "right-hand side has the wrong number of rows";
    return rep;
  }
  if (options_.cycles < 1) {
    rep.status = SolveStatus::failed;
    rep.message = "MultigridOptions::cycles must be at least 1";
    return rep;
  }
  const int k = int(B.cols());
  if (k == 0) return rep;
  m.ensure_buffers(k);
  auto& fine = m.levels.back();
  m.load(fine, fine.b, B);
  m.load(fine, fine.x, X);
  const Eigen::VectorXd bnorm = B.colwise().norm().transpose();
  const int top = int(m.levels.size()) - 1;
  const double tol = options_.tolerance;

  const bool measure_start = tol > 0.0 || options_.measure_contraction;
  // Mixed precision: each cycle runs on the correction of the residual that the previous
  // convergence check kept (correction_cycle).
  const bool mixed = m.fine_single && top > 0;
  double rel =
      measure_start ? m.relative_residual(bnorm, mixed) : std::numeric_limits<double>::infinity();
  bool have_r = measure_start && mixed;
  const double start = rel;
  if (tol > 0.0 && rel < tol) {
    rep.relative_residual = rel;
    return rep;
  }
  rep.status = SolveStatus::max_iterations;
  for (int c = 0; c < std::max(options_.cycles, 0); ++c) {
    if (mixed)
      m.correction_cycle(options_, have_r);
    else
      m.cycle(top, options_);
    const double before = rel;
    rel = m.relative_residual(bnorm, mixed);
    have_r = mixed;
    rep.residuals.push_back(rel);
    rep.iterations = c + 1;
    if (!std::isfinite(rel)) {
      rep.status = SolveStatus::numerical_issue;
      rep.message = "NaN or infinity in the multigrid iterate";
      break;
    }
    if (tol > 0.0 && rel < tol) {
      rep.status = SolveStatus::converged;
      break;
    }
    if (tol > 0.0 && options_.give_up_ratio > 0.0 && rel > options_.give_up_ratio * before) {
      char note[128];
      std::snprintf(note, sizeof note, "a cycle reduced the residual by only %.3g: stopped",
                    rel / before);
      rep.message = note;
      break;
    }
  }
  // Fixed work (no tolerance) ran its cycles without checking where they ended: max_iterations,
  // never `converged` (a guard that checks them against a bound says that:
  // solvers/multigrid_fallback.h), except on a single level, where the cycle is the direct solve.
  if (tol <= 0.0 && top == 0 && rep.iterations > 0 && std::isfinite(rel))
    rep.status = SolveStatus::converged;
  rep.relative_residual = rel;
  if (measure_start && rep.iterations > 0 && std::isfinite(rel) && std::isfinite(start) &&
      start > 0.0)
    rep.contraction = std::pow(rel / start, 1.0 / rep.iterations);
  m.store(fine, fine.x, X);
  return rep;
}

void MultigridSolver::precondition(const Eigen::MatrixXd& r, Eigen::MatrixXd& z) {
  Impl& m = *impl_;
  if (!m.ready) throw std::logic_error("MultigridSolver::precondition before set_matrix");
  const int n = m.levels.back().n();
  if (r.rows() != n) throw std::invalid_argument("MultigridSolver::precondition: wrong size");
  const int k = int(r.cols());
  if (z.rows() != n || z.cols() != k) z.resize(n, k);
  if (k == 0) return;
  m.ensure_buffers(k);
  auto& fine = m.levels.back();
  m.load(fine, fine.b, r);
  m.zero_iterate(fine);
  m.cycle(int(m.levels.size()) - 1, options_);
  m.store(fine, fine.x, z);
}

std::int64_t MultigridSolver::level_sweep_entries(int l) const {
  const auto& L = impl_->levels.at(std::size_t(l));
  std::int64_t diagonal = 0;
  for (int p : L.diag_pos) diagonal += p >= 0 ? 1 : 0;
  return std::int64_t(L.A.nonZeros()) - diagonal;
}
int MultigridSolver::level_sweep_entry_bytes(int l) const {
  const auto& L = impl_->levels.at(std::size_t(l));
  if (L.smoother.empty()) return int(sizeof(int) + sizeof(double));
  return int(sizeof(std::int16_t) + (L.smoother.aligned ? sizeof(double) : sizeof(float)));
}
std::int64_t MultigridSolver::coarsest_factor_nonzeros() const {
  const Impl& m = *impl_;
  if (!m.ready || m.coarse_pinv.size() > 0) return 0;
  return std::int64_t(m.ldlt.matrixL().nestedExpression().nonZeros()) + m.levels.front().n();
}

void MultigridSolver::run_kernel(MultigridKernel kernel, int l, int columns) {
  Impl& m = *impl_;
  if (!m.ready) throw std::logic_error("MultigridSolver::run_kernel before set_matrix");
  const int top = int(m.levels.size()) - 1;
  const bool transfer =
      kernel == MultigridKernel::restriction || kernel == MultigridKernel::prolongation;
  if (l < 0 || l > top || (transfer && l == 0) ||
      (kernel == MultigridKernel::coarsest_solve && l != 0))
    throw std::invalid_argument("MultigridSolver::run_kernel: no such level for this kernel");
  if (columns <= 0) return;
  m.ensure_buffers(columns);
  switch (kernel) {
    case MultigridKernel::forward_sweep:
      m.sweep(l, false);
      break;
    case MultigridKernel::reverse_sweep:
      m.sweep(l, true);
      break;
    case MultigridKernel::residual:
      m.residual(l);
      break;
    case MultigridKernel::restriction:
      m.restrict_residual(l);
      break;
    case MultigridKernel::prolongation:
      m.prolongate(l);
      break;
    case MultigridKernel::coarsest_solve:
      m.coarse_solve();
      break;
  }
}

void MultigridSolver::gauss_seidel(int l, const Eigen::MatrixXd& B, Eigen::MatrixXd& X, int sweeps,
                                   bool reverse) {
  Impl& m = *impl_;
  if (!m.ready) throw std::logic_error("MultigridSolver::gauss_seidel before set_matrix");
  auto& L = m.levels.at(std::size_t(l));
  if (B.rows() != L.n() || X.rows() != L.n() || X.cols() != B.cols())
    throw std::invalid_argument("MultigridSolver::gauss_seidel: wrong size");
  const int k = int(B.cols());
  if (k == 0) return;
  m.ensure_buffers(k);
  m.load(L, L.b, B);
  m.load(L, L.x, X);
  for (int i = 0; i < sweeps; ++i) m.sweep(l, reverse);
  m.store(L, L.x, X);
}

}  // namespace mcf
