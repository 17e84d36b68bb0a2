#include "solvers/multigrid.h"

#include "core/vec4.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <new>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>

namespace mcf {

const char* to_string(MultigridCycle c) {
  return c == MultigridCycle::V ? "V" : "W";
}

namespace {

constexpr int kGrain = 256;         // rows per TBB task
constexpr int kSerialBelow = 2048;  // loops shorter than this run serially (same result)
constexpr int kTile = MultigridSolver::tile_size;
constexpr int kMinBlockTiles = 8;  // tiles per relaxation block, at least (find_blocks())

/// Runs f(begin, end) over [0, n), in parallel when n is large enough. Every kernel writes
/// disjoint outputs and reads nothing that the same loop writes, so the split is irrelevant.
template <class F>
void for_rows(int n, F&& f) {
  if (n < kSerialBelow) {
    f(0, n);
    return;
  }
  tbb::parallel_for(tbb::blocked_range<int>(0, n, kGrain),
                    [&](const tbb::blocked_range<int>& r) { f(r.begin(), r.end()); });
}

// The kernels below cost a few instructions per matrix entry and run at full speed only when
// inlined into their loops: out of line, the two accumulators passed by reference go through
// memory on every entry. GCC stopped inlining gather_sub and gather_sub_compact once they had a
// few more call sites (a fine sweep then took up to 1.5x as long), so they are forced.
#define MCF_KERNEL_INLINE inline __attribute__((always_inline))

// The kernels below hold four right-hand-side columns of one row in one vector (core/vec4.h).
using vec4::load4;
using vec4::splat;
using vec4::store4;
using vec4::v4;

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

/// Raw view of a compressed column-major matrix.
struct Csc {
  int rows = 0, cols = 0;
  const int* outer = nullptr;
  const int* inner = nullptr;
  const double* val = nullptr;
  explicit Csc(const SparseRef& m)
      : rows(int(m.rows())),
        cols(int(m.cols())),
        outer(m.outerIndexPtr()),
        inner(m.innerIndexPtr()),
        val(m.valuePtr()) {}
};

// ---- kernels on interleaved buffers ---------------------------------------------------------
//
// Entry (i, c) of an n x k block lives at i*s + c, with the stride s = k rounded up to a multiple
// of 4 (padding columns are zero and stay zero): every kernel handles four columns of a row as one
// vector, columns o..o+3: one load of a neighbour's iterate instead of three, one vector multiply-
// add instead of three. A row's terms are summed alternately into two vector accumulators (even
// and odd positions of each run of entries), which halves the chain of dependent multiply-adds.
// In a stand-alone Gauss-Seidel kernel on cached data (AMD EPYC guest) this took an entry from
// 3.4 to 2.1 cycles; on the depth-9 levels the sweeps are bound by memory traffic instead
// (SmootherRows, relaxation blocks).

/// Σ_p val[p] x[inner[p]] over p in [begin, end), into acc0 (even p - begin) and acc1 (odd).
MCF_KERNEL_INLINE void gather_sub(const Csc& A, const double* x, std::size_t s, int o, int begin,
                                  int end, v4& acc0, v4& acc1) {
  int p = begin;
  for (; p + 1 < end; p += 2) {
    acc0 -= splat(A.val[p]) * load4(x + std::size_t(A.inner[p]) * s + o);
    acc1 -= splat(A.val[p + 1]) * load4(x + std::size_t(A.inner[p + 1]) * s + o);
  }
  if (p < end) acc0 -= splat(A.val[p]) * load4(x + std::size_t(A.inner[p]) * s + o);
}

/// One Gauss-Seidel update of row i (= column i of the symmetric CSC matrix), columns o..o+3.
/// diag_pos[i] is the position of the diagonal entry in column i (-1 if absent): the sum runs
/// over the entries before and after it, in index order, without a test per entry.
MCF_KERNEL_INLINE void gs_row(const Csc& A, const int* diag_pos, const double* inv_diag,
                              const double* b, double* x, std::size_t s, int o, int i) {
  const std::size_t ii = std::size_t(i) * s + o;
  v4 acc0 = load4(b + ii), acc1 = splat(0.0);
  const int dp = diag_pos[i];
  if (dp >= 0) {
    gather_sub(A, x, s, o, A.outer[i], dp, acc0, acc1);
    gather_sub(A, x, s, o, dp + 1, A.outer[i + 1], acc0, acc1);
  } else {
    gather_sub(A, x, s, o, A.outer[i], A.outer[i + 1], acc0, acc1);
  }
  store4(x + ii, (acc0 + acc1) * splat(inv_diag[i]));
}

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

/// A level's off-diagonal entries as the smoother reads them, each entry's column as (column -
/// row) in 16 bits. The sweeps stream the matrix ten times per level visit and are bound by its
/// bytes once the iterate stays in cache.
/// - Coarse levels: row by row in the internal numbering, the diagonal left out, the values in
///   single precision (6 bytes an entry instead of CSC's 12).
/// - Finest level (`aligned`): one offset per entry of the level's CSC matrix, whose columns store
///   their diagonal last (Impl::symbolic), so a row's off-diagonal entries are one run of the
///   matrix's own values: 10 bytes an entry, and the largest matrix is stored once (no copy of its
///   values beside it). Why not single precision here: a Gauss-Seidel update
///   x_i = (b_i - Σ a_ij x_j) / a_ii with rounded a_ij has the rounded system's solution as its
///   fixed point, so the finest level's sweeps would pull the iterate off A x = b (a test that
///   cycles to 1e-10 stalled at 2e-8); on a coarse level the sweeps only shape a correction of
///   the finest residual, which is exact, so the cycle still converges to the solution of A x = b.
/// Unused when some column lies farther than 16 bits from its row (the sweeps then read the CSC).
struct SmootherRows {
  bool aligned = false;              // finest level: offset[p] belongs to CSC entry p
  std::vector<int> start;            // coarse levels: row i's entries [start[i], start[i+1])
  std::vector<std::int16_t> offset;  // column - row
  std::vector<float> single;         // coarse levels' values
  bool empty() const { return !aligned && start.empty(); }
};

/// acc0/acc1 -= Σ_p val[p] x[i + offset[p]] over the compact entries [begin, end).
template <class V>
MCF_KERNEL_INLINE void gather_sub_compact(const std::int16_t* off, const V* val, const double* xi,
                                          std::size_t s, int begin, int end, v4& acc0, v4& acc1) {
  const std::ptrdiff_t st = std::ptrdiff_t(s);
  int p = begin;
  for (; p + 1 < end; p += 2) {
    acc0 -= splat(double(val[p])) * load4(xi + std::ptrdiff_t(off[p]) * st);
    acc1 -= splat(double(val[p + 1])) * load4(xi + std::ptrdiff_t(off[p + 1]) * st);
  }
  if (p < end) acc0 -= splat(double(val[p])) * load4(xi + std::ptrdiff_t(off[p]) * st);
}

/// gs_row on a coarse level's compact rows (values val: S.single).
template <class V>
MCF_KERNEL_INLINE void gs_row_compact(const SmootherRows& S, const V* val, const double* inv_diag,
                                      const double* b, double* x, std::size_t s, int o, int i) {
  const std::size_t ii = std::size_t(i) * s + o;
  v4 acc0 = load4(b + ii), acc1 = splat(0.0);
  gather_sub_compact(S.offset.data(), val, x + ii, s, S.start[std::size_t(i)],
                     S.start[std::size_t(i) + 1], acc0, acc1);
  store4(x + ii, (acc0 + acc1) * splat(inv_diag[i]));
}

/// gs_row on the finest level's aligned offsets: the row's off-diagonal entries are the run
/// before its diagonal (stored last), read from the matrix itself; bitwise what gs_row_compact
/// computes on a copy of them.
MCF_KERNEL_INLINE void gs_row_aligned(const Csc& A, const std::int16_t* off, const int* diag_pos,
                                      const double* inv_diag, const double* b, double* x,
                                      std::size_t s, int o, int i) {
  const std::size_t ii = std::size_t(i) * s + o;
  v4 acc0 = load4(b + ii), acc1 = splat(0.0);
  const int dp = diag_pos[i];
  gather_sub_compact(off, A.val, x + ii, s, A.outer[i], dp >= 0 ? dp : A.outer[i + 1], acc0, acc1);
  store4(x + ii, (acc0 + acc1) * splat(inv_diag[i]));
}

// ---- sparse products with a precomputed pattern ------------------------------------------

/// Pattern of X * Y (sorted row indices, zero values). Parallel over the columns of Y.
SparseMatrix symbolic_product(const SparseMatrix& Xm, const SparseMatrix& Ym) {
  const Csc X(Xm), Y(Ym);
  const int m = X.rows, q = Y.cols;
  std::vector<std::vector<int>> cols(static_cast<std::size_t>(q));
  tbb::enumerable_thread_specific<std::vector<int>> marks(
      [m] { return std::vector<int>(std::size_t(m), -1); });
  tbb::parallel_for(tbb::blocked_range<int>(0, q, 64), [&](const tbb::blocked_range<int>& r) {
    auto& mark = marks.local();
    for (int J = r.begin(); J < r.end(); ++J) {
      auto& c = cols[std::size_t(J)];
      for (int p = Y.outer[J]; p < Y.outer[J + 1]; ++p) {
        const int t = Y.inner[p];
        for (int a = X.outer[t]; a < X.outer[t + 1]; ++a) {
          const int i = X.inner[a];
          if (mark[std::size_t(i)] != J) {
            mark[std::size_t(i)] = J;
            c.push_back(i);
          }
        }
      }
      std::sort(c.begin(), c.end());
    }
  });
  std::size_t nnz = 0;
  for (const auto& c : cols) nnz += c.size();
  SparseMatrix M(m, q);
  M.resizeNonZeros(Eigen::Index(nnz));
  int* outer = M.outerIndexPtr();
  outer[0] = 0;
  for (int J = 0; J < q; ++J) outer[J + 1] = outer[J] + int(cols[std::size_t(J)].size());
  tbb::parallel_for(0, q, [&](int J) {
    std::copy(cols[std::size_t(J)].begin(), cols[std::size_t(J)].end(),
              M.innerIndexPtr() + outer[J]);
  });
  std::fill(M.valuePtr(), M.valuePtr() + nnz, 0.0);
  return M;
}

using Spa = tbb::enumerable_thread_specific<std::vector<double>>;

/// Values of the Galerkin operator A_c = Pᵀ A P on its precomputed (sorted, symmetric) pattern.
/// Per coarse column J, v = A P e_J is accumulated in a thread-local dense vector, and each entry
/// (I, J) with I <= J is the sparse dot product P e_I · v, written to (I, J) and to its mirror
/// (J, I): A_c is exactly symmetric, the intermediate A P is never stored, and only half of the
/// dot products are formed. Every entry is computed by one task in a fixed order: deterministic.
/// Columns are visited in `column_order` (internal column of the caller's column jj; empty:
/// identity), i.e. in grid order, so consecutive columns share most of their fine support:
/// visiting them colour-major measured 1.3x slower.
void galerkin_values(const SparseMatrix& Am, const SparseMatrix& Pm, SparseMatrix& Cm,
                     const std::vector<int>& transpose_pos, const std::vector<int>& column_order,
                     Spa& spa) {
  const Csc A(Am), P(Pm);
  const int m = A.rows;
  const int* Couter = Cm.outerIndexPtr();
  const int* Cinner = Cm.innerIndexPtr();
  double* Cval = Cm.valuePtr();
  tbb::parallel_for(tbb::blocked_range<int>(0, P.cols, 64), [&](const tbb::blocked_range<int>& r) {
    auto& v = spa.local();
    if (v.size() < std::size_t(m)) v.assign(std::size_t(m), 0.0);
    for (int jj = r.begin(); jj < r.end(); ++jj) {
      const int J = column_order.empty() ? jj : column_order[std::size_t(jj)];
      for (int p = P.outer[J]; p < P.outer[J + 1]; ++p) {
        const int t = P.inner[p];
        const double w = P.val[p];
        for (int a = A.outer[t]; a < A.outer[t + 1]; ++a)
          v[std::size_t(A.inner[a])] += A.val[a] * w;
      }
      for (int e = Couter[J]; e < Couter[J + 1]; ++e) {
        const int I = Cinner[e];
        if (I > J) break;  // sorted: the rest is the mirror of columns > J
        double sum = 0.0;
        for (int q = P.outer[I]; q < P.outer[I + 1]; ++q)
          sum += P.val[q] * v[std::size_t(P.inner[q])];
        Cval[e] = sum;
        const int t = transpose_pos[std::size_t(e)];
        if (t >= 0) Cval[t] = sum;
      }
      for (int p = P.outer[J]; p < P.outer[J + 1]; ++p) {
        const int t = P.inner[p];
        for (int a = A.outer[t]; a < A.outer[t + 1]; ++a) v[std::size_t(A.inner[a])] = 0.0;
      }
    }
  });
}

// ---- the solver's internal numbering -------------------------------------------------------
//
// Each coloured level is stored in tiles of kTile consecutive caller indices, colour-major inside
// each tile (colour 0's functions of the tile first, each colour in index order). A colour pass of
// Gauss-Seidel then streams one contiguous segment per tile instead of every eighth row of the
// whole matrix (the interleaved rows defeated the hardware prefetchers: a sweep on the armadillo
// at depth 9 took 2.1x as long in the solver, 3.5x in a stand-alone kernel benchmark), and the
// rows a coarse function's support touches stay within a few tiles, which keeps the Galerkin
// product's accumulators in cache (a global colour-major order made it 1.6x slower). The parity
// 8-colour ordering and its iterates are unchanged. `perm[r]` is the caller's index of internal
// row r, `inv` its inverse; both are empty for the identity.

int old_index(const std::vector<int>& perm, int r) {
  return perm.empty() ? r : perm[std::size_t(r)];
}
int new_index(const std::vector<int>& inv, int i) {
  return inv.empty() ? i : inv[std::size_t(i)];
}

/// M with entry (i, j) moved to (row_inv[i], col_inv[j]) (col_perm = inverse of col_inv). With
/// `sort` each column is sorted by its new row indices; without, the entries of each column keep
/// their relative order (so a row sum visits its terms in the caller's order).
SparseMatrix permuted(const SparseRef& Mm, const std::vector<int>& row_inv,
                      const std::vector<int>& col_perm, bool sort) {
  const Csc M(Mm);
  SparseMatrix out(M.rows, M.cols);
  out.resizeNonZeros(Mm.nonZeros());
  int* outer = out.outerIndexPtr();
  outer[0] = 0;
  for (int r = 0; r < M.cols; ++r) {
    const int j = old_index(col_perm, r);
    outer[r + 1] = outer[r] + (M.outer[j + 1] - M.outer[j]);
  }
  tbb::parallel_for(tbb::blocked_range<int>(0, M.cols, 1024),
                    [&](const tbb::blocked_range<int>& range) {
                      std::vector<std::pair<int, double>> col;
                      for (int r = range.begin(); r < range.end(); ++r) {
                        const int j = old_index(col_perm, r);
                        col.clear();
                        for (int p = M.outer[j]; p < M.outer[j + 1]; ++p)
                          col.emplace_back(new_index(row_inv, M.inner[p]), M.val[p]);
                        if (sort) std::sort(col.begin(), col.end());
                        for (std::size_t t = 0; t < col.size(); ++t) {
                          out.innerIndexPtr()[outer[r] + int(t)] = col[t].first;
                          out.valuePtr()[outer[r] + int(t)] = col[t].second;
                        }
                      }
                    });
  return out;
}

/// Whether `stored` == permuted(given, row_inv, col_perm, sort) (pattern, and values when asked)
/// without building the permuted copy. Unsorted, with diag_rank (the finest level): column r
/// stores the caller's diag_rank[r]-th entry last (Impl::diagonal_last).
bool same_permuted(const SparseMatrix& stored, const SparseRef& given,
                   const std::vector<int>& row_inv, const std::vector<int>& col_perm, bool sort,
                   bool values, const std::vector<int>& diag_rank = {}) {
  if (stored.rows() != given.rows() || stored.cols() != given.cols() ||
      stored.nonZeros() != given.nonZeros() || !given.isCompressed())
    return false;
  const Csc S(stored), G(given);
  return tbb::parallel_reduce(
      tbb::blocked_range<int>(0, S.cols, 1024), true,
      [&](const tbb::blocked_range<int>& range, bool ok) {
        for (int r = range.begin(); ok && r < range.end(); ++r) {
          const int j = old_index(col_perm, r);
          const int n = G.outer[j + 1] - G.outer[j];
          const int k = diag_rank.empty() ? -1 : diag_rank[std::size_t(r)];
          if (n != S.outer[r + 1] - S.outer[r]) return false;
          const int* sb = S.inner + S.outer[r];
          const int* se = sb + n;
          for (int t = 0; t < n; ++t) {
            const int p = G.outer[j] + t;
            const int i = new_index(row_inv, G.inner[p]);
            // Unsorted: entry t in place. Sorted: somewhere in the column (rows are distinct and
            // the counts equal, so finding every given entry proves equality).
            const int slot = k < 0 || t < k ? t : (t == k ? n - 1 : t - 1);
            const int* it = sort ? std::lower_bound(sb, se, i) : sb + slot;
            if (it == se || *it != i || (values && S.val[it - S.inner] != G.val[p])) return false;
          }
        }
        return ok;
      },
      [](bool a, bool b) { return a && b; });
}

}  // namespace

// ------------------------------------------------------------------------------------------

struct MultigridSolver::Impl {
  struct Level {
    // All matrices and buffers of a level are in its internal numbering (tile-wise colour-major
    // when colours were given; see number_by_colour()).
    SparseMatrix A;                  // compressed, symmetric pattern; coarse levels sorted
    std::vector<int> perm, inv;      // internal row r <-> caller's index perm[r]; empty: identity
    std::vector<int> transpose_pos;  // entry e=(i,J) -> position of (J,i) (coarse levels)
    std::vector<double> inv_diag;
    std::vector<int> diag_pos;  // position of the diagonal entry of each column, -1 if none
    // Finest level of a hierarchy: each column stores its diagonal last (the smoother reads the
    // off-diagonal run in place); diag_rank[r] = the diagonal's place in the caller's column
    // (-1: none). Empty on coarse levels and a single level.
    std::vector<int> diag_rank;
    bool coloured = false;
    std::vector<int> segment_start;  // rows of colour c in tile t: [s[8t+c], s[8t+c+1])
    int block_tiles = 1;             // tiles per relaxation block (find_blocks())
    SmootherRows smoother;           // compact off-diagonal rows for the sweeps (may be empty)
    int tiles() const { return int(segment_start.size() / 8); }
    int blocks() const { return (tiles() + block_tiles - 1) / block_tiles; }
    // Transfer to the next finer level (absent on the finest level).
    SparseMatrix P;   // n_{l+1} x n_l
    SparseMatrix PT;  // n_l x n_{l+1}
    Spa spa;          // dense accumulators of the Galerkin product
    // Work buffers (interleaved n x k, row stride padded to a multiple of 4).
    Buffer x, b, r;
    int n() const { return int(A.rows()); }
  };

  std::vector<Level> levels;                       // coarsest first
  std::vector<std::vector<std::uint8_t>> colours;  // as given (to detect changes)
  Eigen::SimplicialLDLT<SparseMatrix> ldlt;
  // The coarsest solve when its matrix is only semi-definite (set_matrix: coarsest_pseudo_inverse):
  // a dense generalized inverse, empty while the LDLᵀ factor serves.
  Eigen::MatrixXd coarse_pinv;
  Eigen::MatrixXd coarse_rhs, coarse_sol;
  int k = 0;          // columns the buffers are sized for
  std::size_t s = 0;  // their row stride: k rounded up to a multiple of 4
  bool ready = false;
  std::int64_t symbolic_builds = 0, numeric_builds = 0, pattern_comparisons = 0;
  std::uint64_t pattern_key = 0;         // the key the current pattern was set with (0: none)
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

  /// The level's internal numbering from its given colours: blocks of kTile consecutive caller
  /// indices, colour-major inside each block (identity when no colours are given, their count is
  /// wrong or a colour is out of 0..7). Segment (t, c) = rows of colour c in block t.
  static void number_by_colour(Level& L, int n, const std::vector<std::uint8_t>* given) {
    L.perm.clear();
    L.inv.clear();
    L.segment_start.clear();
    if (given == nullptr || int(given->size()) != n) return;
    const auto& col = *given;
    for (int i = 0; i < n; ++i)
      if (col[std::size_t(i)] > 7) return;
    const int tiles = (n + kTile - 1) / kTile;
    L.segment_start.assign(std::size_t(tiles) * 8 + 1, 0);
    for (int i = 0; i < n; ++i)
      ++L.segment_start[std::size_t(i / kTile) * 8 + col[std::size_t(i)] + 1];
    for (std::size_t q = 1; q < L.segment_start.size(); ++q)
      L.segment_start[q] += L.segment_start[q - 1];
    L.perm.resize(std::size_t(n));
    L.inv.resize(std::size_t(n));
    std::vector<int> fill(L.segment_start.begin(), L.segment_start.end() - 1);
    for (int i = 0; i < n; ++i) {
      const int r = fill[std::size_t(i / kTile) * 8 + col[std::size_t(i)]]++;
      L.perm[std::size_t(r)] = i;
      L.inv[std::size_t(i)] = r;
    }
  }

  /// A numbered level is coloured when no two functions of one colour couple (checked on the
  /// level's matrix pattern with its given colours); otherwise it is relaxed serially in its
  /// internal order.
  static void check_colouring(Level& L, const std::vector<std::uint8_t>* given) {
    L.coloured = false;
    if (L.perm.empty()) return;
    const auto colour = [&](int r) { return (*given)[std::size_t(L.perm[std::size_t(r)])]; };
    const Csc A(L.A);
    const bool ok = tbb::parallel_reduce(
        tbb::blocked_range<int>(0, L.n(), 4096), true,
        [&](const tbb::blocked_range<int>& rows, bool good) {
          for (int r = rows.begin(); good && r < rows.end(); ++r)
            for (int p = A.outer[r]; p < A.outer[r + 1]; ++p) {
              const int q = A.inner[p];
              if (q != r && colour(q) == colour(r)) {
                good = false;
                break;
              }
            }
          return good;
        },
        [](bool x, bool y) { return x && y; });
    L.coloured = ok;
  }

  static void find_diagonal(Level& L) {
    const Csc A(L.A);
    L.diag_pos.assign(std::size_t(L.n()), -1);
    for_rows(L.n(), [&](int b, int e) {
      for (int i = b; i < e; ++i)
        for (int p = A.outer[i]; p < A.outer[i + 1]; ++p)
          if (A.inner[p] == i) {
            L.diag_pos[std::size_t(i)] = p;
            break;
          }
    });
  }

  /// Relaxation blocks of a coloured level (header, "Smoother ordering"): runs of `block_tiles`
  /// consecutive tiles, at least as many as the farthest coupling reaches (in tiles), so rows of
  /// block q couple only with blocks q-1, q, q+1 and blocks of one parity never couple.
  /// A block's rows and iterates stay in cache through its eight colours (on the armadillo at
  /// depth 9 the farthest coupling reaches 9 tiles). A floor of kMinBlockTiles (8) instead of 1
  /// costs nothing measurable there and keeps small levels from being cut into many tiny tasks.
  static void find_blocks(Level& L) {
    L.block_tiles = 1;
    if (!L.coloured) return;
    const Csc A(L.A);
    const int reach = tbb::parallel_reduce(
        tbb::blocked_range<int>(0, L.n(), 4096), 0,
        [&](const tbb::blocked_range<int>& rows, int far) {
          for (int r = rows.begin(); r < rows.end(); ++r)
            for (int p = A.outer[r]; p < A.outer[r + 1]; ++p)
              far = std::max(far, std::abs(A.inner[p] / kTile - r / kTile));
          return far;
        },
        [](int a, int b) { return std::max(a, b); });
    L.block_tiles = std::max(reach, kMinBlockTiles);
  }

  /// The compact rows' pattern (SmootherRows), or none when an offset does not fit 16 bits: on
  /// the finest level one offset per CSC entry (aligned; its values are the matrix's own), on
  /// coarse levels the off-diagonal entries only, with room for their single-precision values.
  static void smoother_pattern(Level& L, bool finest) {
    SmootherRows& S = L.smoother;
    S = SmootherRows{};
    if (!L.coloured) return;  // the serial fallback reads the double-precision matrix
    const Csc A(L.A);
    const auto fits16 = [](int d) { return d >= INT16_MIN && d <= INT16_MAX; };
    if (finest) {
      std::vector<std::int16_t> offset(std::size_t(A.outer[A.cols]));
      for (int i = 0; i < L.n(); ++i)
        for (int p = A.outer[i]; p < A.outer[i + 1]; ++p) {
          const int d = A.inner[p] - i;
          if (!fits16(d)) return;
          offset[std::size_t(p)] = std::int16_t(d);
        }
      S.offset = std::move(offset);
      S.aligned = true;
      return;
    }
    std::vector<int> start(std::size_t(L.n()) + 1, 0);
    for (int i = 0; i < L.n(); ++i) {
      const int dp = L.diag_pos[std::size_t(i)];
      start[std::size_t(i) + 1] =
          start[std::size_t(i)] + (A.outer[i + 1] - A.outer[i]) - (dp >= 0 ? 1 : 0);
    }
    std::vector<std::int16_t> offset(std::size_t(start.back()));
    for (int i = 0; i < L.n(); ++i) {
      int e = start[std::size_t(i)];
      for (int p = A.outer[i]; p < A.outer[i + 1]; ++p) {
        const int d = A.inner[p] - i;
        if (d == 0) continue;
        if (!fits16(d)) return;
        offset[std::size_t(e++)] = std::int16_t(d);
      }
    }
    S.start = std::move(start);
    S.offset = std::move(offset);
    S.single.assign(S.offset.size(), 0.0f);
  }

  /// A coarse level's compact values from its matrix (same order, diagonal skipped, rounded to
  /// single precision). The finest level's sweeps read the matrix's own values.
  static void smoother_values(Level& L) {
    SmootherRows& S = L.smoother;
    if (S.empty() || S.aligned) return;
    const Csc A(L.A);
    // A row's off-diagonal entries are the runs before and after its diagonal (diag_pos), so they
    // are copied as two runs without reading the row indices.
    float* out = S.single.data();
    for_rows(L.n(), [&](int b, int e) {
      for (int i = b; i < e; ++i) {
        const int p0 = A.outer[i], p1 = A.outer[i + 1], dp = L.diag_pos[std::size_t(i)];
        float* q = out + S.start[std::size_t(i)];
        if (dp < 0) {
          std::copy(A.val + p0, A.val + p1, q);
        } else {
          q = std::copy(A.val + p0, A.val + dp, q);
          std::copy(A.val + dp + 1, A.val + p1, q);
        }
      }
    });
  }

  /// Moves each column's diagonal entry of the finest matrix to the column's end (the other
  /// entries keep their order) and records where it was (diag_rank).
  static void diagonal_last(Level& F) {
    int* outer = F.A.outerIndexPtr();
    int* inner = F.A.innerIndexPtr();
    double* val = F.A.valuePtr();
    F.diag_rank.assign(std::size_t(F.n()), -1);
    for_rows(F.n(), [&](int b, int e) {
      for (int r = b; r < e; ++r) {
        const int p0 = outer[r], p1 = outer[r + 1];
        const int* d = std::find(inner + p0, inner + p1, r);
        if (d == inner + p1) continue;
        const int k = int(d - (inner + p0));
        F.diag_rank[std::size_t(r)] = k;
        std::rotate(inner + p0 + k, inner + p0 + k + 1, inner + p1);
        std::rotate(val + p0 + k, val + p0 + k + 1, val + p1);
      }
    });
  }

  void symbolic(const SparseRef& A, const std::vector<SparseMatrix>& P,
                const std::vector<std::vector<std::uint8_t>>* given_colours) {
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
    if (nl > 1) diagonal_last(F);
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
      const Csc M(C.A);
      C.transpose_pos.assign(std::size_t(C.A.nonZeros()), -1);
      tbb::parallel_for(0, M.cols, [&](int J) {
        for (int e = M.outer[J]; e < M.outer[J + 1]; ++e) {
          const int i = M.inner[e];
          const int* b = M.inner + M.outer[i];
          const int* en = M.inner + M.outer[i + 1];
          const int* it = std::lower_bound(b, en, J);
          if (it != en && *it == J) C.transpose_pos[std::size_t(e)] = int(it - M.inner);
        }
      });
    }
    for (std::size_t l = 0; l < nl; ++l) {
      check_colouring(levels[l], l < colours.size() ? &colours[l] : nullptr);
      find_diagonal(levels[l]);
      find_blocks(levels[l]);
      smoother_pattern(levels[l], l + 1 == nl);
    }
    k = 0;
    work.assign(nl, MultigridLevelWork{});
    ++symbolic_builds;
  }

  /// New values of the finest matrix (same pattern as the stored one, in the caller's numbering):
  /// A's, or the sum's entry by entry when one is given (its terms on A's pattern, A its M;
  /// sum_entry, so bitwise what sum_on_pattern would have handed to set_matrix).
  void set_fine_values(const SparseRef& A, const MatrixSum* sum) {
    Level& F = levels.back();
    const Csc G(A);
    const int* outer = F.A.outerIndexPtr();
    double* val = F.A.valuePtr();
    const double* kv = sum ? sum->K.valuePtr() : nullptr;
    const double* sv = sum && sum->S ? sum->S->valuePtr() : nullptr;
    const double a = sum ? sum->a : 1.0, b = sum ? sum->b : 0.0, s = sum ? sum->s : 0.0;
    // Caller's entries [p, q) of column j to out: copied, or summed with the other terms'.
    const auto put = [&](int p, int q, double* out) {
      if (!kv) return std::copy(G.val + p, G.val + q, out);
      if (sv)
        for (; p < q; ++p) *out++ = sum_entry(a, G.val[p], b, kv[p], s, sv[p]);
      else
        for (; p < q; ++p) *out++ = sum_entry(a, G.val[p], b, kv[p]);
      return out;
    };
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

  /// Numerical values of all levels from the finest level's values (already in place).
  /// Returns false when a diagonal entry is negative or not finite.
  bool numeric() {
    for (std::size_t l = levels.size() - 1; l-- > 0;) {
      Level& C = levels[l];
      galerkin_values(levels[l + 1].A, C.P, C.A, C.transpose_pos, C.inv, C.spa);
    }
    bool ok = true;
    for (auto& L : levels) {
      const Csc A(L.A);
      L.inv_diag.assign(std::size_t(L.n()), 0.0);
      for (int i = 0; i < L.n(); ++i) {
        const int p = L.diag_pos[std::size_t(i)];
        const double d = p >= 0 ? A.val[p] : 0.0;
        if (!(d >= 0.0) || !std::isfinite(d)) ok = false;
        L.inv_diag[std::size_t(i)] = d > 0.0 ? 1.0 / d : 0.0;
      }
      smoother_values(L);
    }
    ++numeric_builds;
    return ok;
  }

  // ---- cycle ----

  // The relaxation order (header, "Smoother ordering") in one place, for sweep() and
  // relaxation_order(): a sweep is two passes, pass pi relaxing the blocks of parity
  // block_parity(pi, reverse); block q is relaxed colour by colour, tiles ascending, and
  // for_block_segments calls f(r0, r1) for each run of internal rows in that order.
  static int block_parity(int pi, bool reverse) { return reverse ? 1 - pi : pi; }
  template <class F>
  static void for_block_segments(const Level& L, int q, bool reverse, F&& f) {
    const int t0 = q * L.block_tiles, t1 = std::min(L.tiles(), t0 + L.block_tiles);
    for (int ci = 0; ci < 8; ++ci) {
      const std::size_t c = std::size_t(reverse ? 7 - ci : ci);
      for (int t = t0; t < t1; ++t) {
        const std::size_t q8 = std::size_t(t) * 8 + c;
        f(L.segment_start[q8], L.segment_start[q8 + 1]);
      }
    }
  }

  void sweep(int l, bool reverse) {
    Level& L = levels[std::size_t(l)];
    const Csc A(L.A);
    const double* id = L.inv_diag.data();
    const int* dp = L.diag_pos.data();
    const double* b = L.b.data();
    double* x = L.x.data();
    for (int o = 0; o < int(s); o += 4) {
      if (L.coloured) {
        const SmootherRows& S = L.smoother;
        const auto relax_block = [&](int q) {
          for_block_segments(L, q, reverse, [&](int r0, int r1) {
            if (S.aligned) {
              for (int r = r0; r < r1; ++r)
                gs_row_aligned(A, S.offset.data(), dp, id, b, x, s, o, r);
            } else if (!S.empty()) {
              for (int r = r0; r < r1; ++r) gs_row_compact(S, S.single.data(), id, b, x, s, o, r);
            } else {
              for (int r = r0; r < r1; ++r) gs_row(A, dp, id, b, x, s, o, r);
            }
          });
        };
        const int blocks = L.blocks();
        for (int pi = 0; pi < 2; ++pi) {
          const int parity = block_parity(pi, reverse);
          const int count = (blocks - parity + 1) / 2;  // blocks parity, parity + 2, ...
          if (count <= 1) {
            for (int j = 0; j < count; ++j) relax_block(parity + 2 * j);
            continue;
          }
          tbb::parallel_for(tbb::blocked_range<int>(0, count, 1),
                            [&](const tbb::blocked_range<int>& r) {
                              for (int j = r.begin(); j < r.end(); ++j) relax_block(parity + 2 * j);
                            });
        }
      } else if (!reverse) {
        for (int i = 0; i < A.cols; ++i) gs_row(A, dp, id, b, x, s, o, i);
      } else {
        for (int i = A.cols - 1; i >= 0; --i) gs_row(A, dp, id, b, x, s, o, i);
      }
    }
  }

  /// The caller's indices of level l in the order sweep(l, reverse) relaxes them (serially).
  std::vector<int> relaxation_order(int l, bool reverse) const {
    const Level& L = levels[std::size_t(l)];
    std::vector<int> order;
    order.reserve(std::size_t(L.n()));
    if (L.coloured) {
      for (int pi = 0; pi < 2; ++pi)
        for (int q = block_parity(pi, reverse); q < L.blocks(); q += 2)
          for_block_segments(L, q, reverse, [&](int r0, int r1) {
            for (int r = r0; r < r1; ++r) order.push_back(old_index(L.perm, r));
          });
    } else {
      for (int i = 0; i < L.n(); ++i)
        order.push_back(old_index(L.perm, reverse ? L.n() - 1 - i : i));
    }
    return order;
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
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < k; ++c) coarse_rhs(i, c) = L.b[std::size_t(i) * s + std::size_t(c)];
    if (coarse_pinv.size() > 0)
      coarse_sol.noalias() = coarse_pinv * coarse_rhs;
    else
      coarse_sol = ldlt.solve(coarse_rhs);
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < k; ++c) L.x[std::size_t(i) * s + std::size_t(c)] = coarse_sol(i, c);
  }

  // Two clock reads per level visit (a W-cycle at depth 9 makes 384): noise next to the sweeps.
  using Clock = std::chrono::steady_clock;
  static double since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
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
    Level& F = levels[std::size_t(l)];
    Level& C = levels[std::size_t(l) - 1];
    for (int i = 0; i < opt.pre_smooth; ++i) sweep(l, false);
    residual(l);
    // Restriction: b_C = Pᵀ r_F (gather over the columns of P).
    const Csc P(C.P), PT(C.PT);
    for (int o = 0; o < int(s); o += 4)
      for_rows(P.cols,
               [&](int b, int e) { transpose_rows<false>(P, F.r.data(), C.b.data(), s, o, b, e); });
    std::fill(C.x.begin(), C.x.end(), 0.0);
    // γ = 2 for W; an exact coarsest solve is never repeated (it would change nothing).
    const int gamma = (opt.cycle == MultigridCycle::W && l - 1 > 0) ? 2 : 1;
    const auto tc = Clock::now();
    for (int g = 0; g < gamma; ++g) cycle(l - 1, opt);
    const double coarser = since(tc);  // the recursion's time, not this level's own
    // Prolongation: x_F += P x_C (gather over the columns of Pᵀ = rows of P).
    for (int o = 0; o < int(s); o += 4)
      for_rows(PT.cols,
               [&](int b, int e) { transpose_rows<true>(PT, C.x.data(), F.x.data(), s, o, b, e); });
    for (int i = 0; i < opt.post_smooth; ++i) sweep(l, true);
    w.seconds += since(t0) - coarser;
  }

  /// max over columns of ||b - A x|| / ||b|| on the finest level (deterministic reduction).
  double relative_residual(const Eigen::VectorXd& bnorm) {
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
bool MultigridSolver::level_is_coloured(int l) const {
  return impl_->levels.at(std::size_t(l)).coloured;
}
bool MultigridSolver::level_has_compact_smoother(int l) const {
  const auto& L = impl_->levels.at(std::size_t(l));
  return L.coloured && !L.smoother.empty();
}
std::vector<int> MultigridSolver::relaxation_blocks(int l) const {
  const auto& L = impl_->levels.at(std::size_t(l));
  std::vector<int> block(std::size_t(L.n()), 0);
  if (!L.coloured) return block;
  // Block membership as the sweep itself walks it (for_block_segments), not re-derived here.
  for (int q = 0; q < L.blocks(); ++q)
    Impl::for_block_segments(L, q, false, [&](int r0, int r1) {
      for (int r = r0; r < r1; ++r) block[std::size_t(old_index(L.perm, r))] = q;
    });
  return block;
}
std::vector<int> MultigridSolver::relaxation_order(int l, bool reverse) const {
  (void)impl_->levels.at(std::size_t(l));
  return impl_->relaxation_order(l, reverse);
}
std::int64_t MultigridSolver::symbolic_builds() const {
  return impl_->symbolic_builds;
}
std::int64_t MultigridSolver::numeric_builds() const {
  return impl_->numeric_builds;
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
  if (need_symbolic) m.symbolic(A, P, colours);
  if (!need_symbolic || sum) m.set_fine_values(A, sum);
  m.pattern_key = key;
  const bool diag_ok = m.numeric();

  if (need_symbolic) m.ldlt.analyzePattern(m.levels.front().A);
  m.ldlt.factorize(m.levels.front().A);
  if (!diag_ok)
    return fail(SolveStatus::not_positive_definite, "negative or non-finite diagonal entry");
  m.coarse_pinv.resize(0, 0);
  if (!m.coarsest_factor_is_sound()) {
    // The octree's functions on a flat face parallel to a grid plane (the cubical spiral, a
    // box) are linearly dependent on the surface: A is then only semi-definite, on every level.
    // Gauss–Seidel relaxes such a consistent system as it does a definite one (the paper's
    // solver never factors the fine matrix); the coarsest level needs a generalized inverse.
    int null_dimension = 0;
    const std::string why = m.coarsest_pseudo_inverse(null_dimension);
    if (!why.empty()) return fail(SolveStatus::not_positive_definite, why);
    rep.message = "coarsest level semi-definite (null space of dimension " +
                  std::to_string(null_dimension) + "): solved by its pseudo-inverse";
  }
  for (std::size_t l = 1; l < m.levels.size(); ++l)
    if (!m.levels[l].coloured)
      rep.message += (rep.message.empty() ? "" : "; ") + std::string("level ") + std::to_string(l) +
                     " uses serial Gauss-Seidel (no valid colouring)";
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
  const int k = int(B.cols());
  if (k == 0) return rep;
  m.ensure_buffers(k);
  auto& fine = m.levels.back();
  m.load(fine, fine.b, B);
  m.load(fine, fine.x, X);
  const Eigen::VectorXd bnorm = B.colwise().norm().transpose();
  const int top = int(m.levels.size()) - 1;
  const double tol = options_.tolerance;

  double rel = tol > 0.0 ? m.relative_residual(bnorm) : std::numeric_limits<double>::infinity();
  if (tol > 0.0 && rel < tol) {
    rep.relative_residual = rel;
    return rep;
  }
  rep.status = SolveStatus::max_iterations;
  for (int c = 0; c < std::max(options_.cycles, 0); ++c) {
    m.cycle(top, options_);
    rel = m.relative_residual(bnorm);
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
  }
  if (tol <= 0.0 && rep.status == SolveStatus::max_iterations && std::isfinite(rel))
    rep.status = SolveStatus::converged;
  if (rep.iterations == 0 && tol <= 0.0) {  // cycles == 0: report the warm start's residual
    rel = m.relative_residual(bnorm);
    rep.status = std::isfinite(rel) ? SolveStatus::converged : SolveStatus::numerical_issue;
  }
  rep.relative_residual = rel;
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
  std::fill(fine.x.begin(), fine.x.end(), 0.0);
  m.cycle(int(m.levels.size()) - 1, options_);
  m.store(fine, fine.x, z);
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
