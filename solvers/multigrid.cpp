#include "solvers/multigrid.h"

#include <Eigen/SparseCholesky>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>

namespace mcf {

const char* to_string(MultigridCycle c) { return c == MultigridCycle::V ? "V" : "W"; }

namespace {

constexpr int kGrain = 256;            // rows per TBB task
constexpr int kSerialBelow = 2048;     // loops shorter than this run serially (same result)
constexpr int kTile = MultigridSolver::tile_size;

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

template <int K>
using Cols = std::integral_constant<int, K>;

/// Splits k right-hand sides into chunks of at most 4 columns (the columns are independent in
/// every kernel, so this changes nothing but the code the compiler can unroll).
template <class F>
void for_column_chunks(int k, F&& f) {
  int o = 0;
  for (; k - o >= 4; o += 4) f(Cols<4>{}, o);
  switch (k - o) {
    case 1: f(Cols<1>{}, o); break;
    case 2: f(Cols<2>{}, o); break;
    case 3: f(Cols<3>{}, o); break;
    default: break;
  }
}

/// Raw view of a compressed column-major matrix.
struct Csc {
  int rows = 0, cols = 0;
  const int* outer = nullptr;
  const int* inner = nullptr;
  const double* val = nullptr;
  explicit Csc(const SparseMatrix& m)
      : rows(int(m.rows())), cols(int(m.cols())), outer(m.outerIndexPtr()),
        inner(m.innerIndexPtr()), val(m.valuePtr()) {}
};

// ---- kernels on interleaved buffers: entry (i, c) of an n x k block lives at i*s + c -------

/// One Gauss-Seidel update of row i (= column i of the symmetric CSC matrix), columns o..o+K-1.
/// diag_pos[i] is the position of the diagonal entry in column i (-1 if absent): the sum runs
/// over the entries before and after it, in index order, without a test per entry.
template <int K>
inline void gs_row(const Csc& A, const int* diag_pos, const double* inv_diag, const double* b,
                   double* x, std::size_t s, int o, int i) {
  double acc[K];
  const std::size_t ii = std::size_t(i) * s + o;
  for (int c = 0; c < K; ++c) acc[c] = b[ii + c];
  const int dp = diag_pos[i];
  const int split = dp >= 0 ? dp : A.outer[i + 1];
  const auto add = [&](int begin, int end) {
    for (int p = begin; p < end; ++p) {
      const double a = A.val[p];
      const double* xj = x + std::size_t(A.inner[p]) * s + o;
      for (int c = 0; c < K; ++c) acc[c] -= a * xj[c];
    }
  };
  add(A.outer[i], split);
  if (dp >= 0) add(dp + 1, A.outer[i + 1]);
  const double d = inv_diag[i];
  for (int c = 0; c < K; ++c) x[ii + c] = acc[c] * d;
}

/// r = b - A x (rows [begin, end)).
template <int K>
inline void residual_rows(const Csc& A, const double* b, const double* x, double* r, std::size_t s,
                          int o, int begin, int end) {
  for (int i = begin; i < end; ++i) {
    double acc[K];
    const std::size_t ii = std::size_t(i) * s + o;
    for (int c = 0; c < K; ++c) acc[c] = b[ii + c];
    for (int p = A.outer[i]; p < A.outer[i + 1]; ++p) {
      const double a = A.val[p];
      const double* xj = x + std::size_t(A.inner[p]) * s + o;
      for (int c = 0; c < K; ++c) acc[c] -= a * xj[c];
    }
    for (int c = 0; c < K; ++c) r[ii + c] = acc[c];
  }
}

/// y = Mᵀ v (or y += Mᵀ v when Add) on output rows [begin, end) = columns of M (gather along
/// columns, so parallel output ranges never write the same entry).
template <int K, bool Add>
inline void transpose_rows(const Csc& M, const double* v, double* y, std::size_t s, int o, int begin, int end) {
  for (int J = begin; J < end; ++J) {
    double acc[K] = {};
    for (int p = M.outer[J]; p < M.outer[J + 1]; ++p) {
      const double w = M.val[p];
      const double* vi = v + std::size_t(M.inner[p]) * s + o;
      for (int c = 0; c < K; ++c) acc[c] += w * vi[c];
    }
    double* yJ = y + std::size_t(J) * s + o;
    for (int c = 0; c < K; ++c) yJ[c] = Add ? yJ[c] + acc[c] : acc[c];
  }
}

// ---- sparse products with a precomputed pattern ------------------------------------------

/// Pattern of X * Y (sorted row indices, zero values). Parallel over the columns of Y.
SparseMatrix symbolic_product(const SparseMatrix& Xm, const SparseMatrix& Ym) {
  const Csc X(Xm), Y(Ym);
  const int m = X.rows, q = Y.cols;
  std::vector<std::vector<int>> cols(static_cast<std::size_t>(q));
  tbb::enumerable_thread_specific<std::vector<int>> marks([m] { return std::vector<int>(std::size_t(m), -1); });
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
    std::copy(cols[std::size_t(J)].begin(), cols[std::size_t(J)].end(), M.innerIndexPtr() + outer[J]);
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
                     const std::vector<int>& transpose_pos, const std::vector<int>& column_order, Spa& spa) {
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
        for (int a = A.outer[t]; a < A.outer[t + 1]; ++a) v[std::size_t(A.inner[a])] += A.val[a] * w;
      }
      for (int e = Couter[J]; e < Couter[J + 1]; ++e) {
        const int I = Cinner[e];
        if (I > J) break;  // sorted: the rest is the mirror of columns > J
        double sum = 0.0;
        for (int q = P.outer[I]; q < P.outer[I + 1]; ++q) sum += P.val[q] * v[std::size_t(P.inner[q])];
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
// product's accumulators in cache (a global colour-major order made it 1.6x slower). DESIGN.md's
// 8-colour ordering and its iterates are unchanged. `perm[r]` is the caller's index of internal
// row r, `inv` its inverse; both are empty for the identity.

int old_index(const std::vector<int>& perm, int r) { return perm.empty() ? r : perm[std::size_t(r)]; }
int new_index(const std::vector<int>& inv, int i) { return inv.empty() ? i : inv[std::size_t(i)]; }

/// M with entry (i, j) moved to (row_inv[i], col_inv[j]) (col_perm = inverse of col_inv). With
/// `sort` each column is sorted by its new row indices; without, the entries of each column keep
/// their relative order (so a row sum visits its terms in the caller's order).
SparseMatrix permuted(const SparseMatrix& Mm, const std::vector<int>& row_inv, const std::vector<int>& col_perm,
                      bool sort) {
  const Csc M(Mm);
  SparseMatrix out(M.rows, M.cols);
  out.resizeNonZeros(Mm.nonZeros());
  int* outer = out.outerIndexPtr();
  outer[0] = 0;
  for (int r = 0; r < M.cols; ++r) {
    const int j = old_index(col_perm, r);
    outer[r + 1] = outer[r] + (M.outer[j + 1] - M.outer[j]);
  }
  tbb::parallel_for(tbb::blocked_range<int>(0, M.cols, 1024), [&](const tbb::blocked_range<int>& range) {
    std::vector<std::pair<int, double>> col;
    for (int r = range.begin(); r < range.end(); ++r) {
      const int j = old_index(col_perm, r);
      col.clear();
      for (int p = M.outer[j]; p < M.outer[j + 1]; ++p) col.emplace_back(new_index(row_inv, M.inner[p]), M.val[p]);
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
/// without building the permuted copy.
bool same_permuted(const SparseMatrix& stored, const SparseMatrix& given, const std::vector<int>& row_inv,
                   const std::vector<int>& col_perm, bool sort, bool values) {
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
          if (n != S.outer[r + 1] - S.outer[r]) return false;
          const int* sb = S.inner + S.outer[r];
          const int* se = sb + n;
          for (int t = 0; t < n; ++t) {
            const int p = G.outer[j] + t;
            const int i = new_index(row_inv, G.inner[p]);
            // Unsorted: entry t in place. Sorted: somewhere in the column (rows are distinct and
            // the counts equal, so finding every given entry proves equality).
            const int* it = sort ? std::lower_bound(sb, se, i) : sb + t;
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
    SparseMatrix A;                    // compressed, symmetric pattern; coarse levels sorted
    std::vector<int> perm, inv;        // internal row r <-> caller's index perm[r]; empty: identity
    std::vector<int> transpose_pos;    // entry e=(i,J) -> position of (J,i) (coarse levels)
    std::vector<double> inv_diag;
    std::vector<int> diag_pos;         // position of the diagonal entry of each column, -1 if none
    bool coloured = false;
    std::vector<int> segment_start;    // rows of colour c in tile t: [s[8t+c], s[8t+c+1])
    // Transfer to the next finer level (absent on the finest level).
    SparseMatrix P;                    // n_{l+1} x n_l
    SparseMatrix PT;                   // n_l x n_{l+1}
    Spa spa;                           // dense accumulators of the Galerkin product
    // Work buffers (interleaved n x k).
    std::vector<double> x, b, r;
    int n() const { return int(A.rows()); }
  };

  std::vector<Level> levels;           // coarsest first
  std::vector<std::vector<std::uint8_t>> colours;  // as given (to detect changes)
  Eigen::SimplicialLDLT<SparseMatrix> ldlt;
  Eigen::MatrixXd coarse_rhs, coarse_sol;
  int k = 0;                           // columns the buffers are sized for
  bool ready = false;
  std::int64_t symbolic_builds = 0, numeric_builds = 0, pattern_comparisons = 0;
  std::uint64_t pattern_key = 0;       // the key the current pattern was set with (0: none)
  std::vector<MultigridLevelWork> work;  // per level, coarsest first (level_work())

  void ensure_buffers(int cols) {
    if (cols == k) return;
    k = cols;
    for (auto& L : levels) {
      const std::size_t sz = std::size_t(L.n()) * std::size_t(k);
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
    for (int i = 0; i < n; ++i) ++L.segment_start[std::size_t(i / kTile) * 8 + col[std::size_t(i)] + 1];
    for (std::size_t q = 1; q < L.segment_start.size(); ++q) L.segment_start[q] += L.segment_start[q - 1];
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

  void symbolic(const SparseMatrix& A, const std::vector<SparseMatrix>& P,
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
    // The finest matrix keeps each column's entries in the caller's order, so later value
    // updates are one block copy per column (set_fine_values) and row sums add their terms in
    // the caller's order.
    Level& F = levels.back();
    F.A = permuted(A, F.inv, F.perm, false);
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
    }
    k = 0;
    work.assign(nl, MultigridLevelWork{});
    ++symbolic_builds;
  }

  /// New values of the finest matrix (same pattern as the stored one, in the caller's numbering).
  void set_fine_values(const SparseMatrix& A) {
    Level& F = levels.back();
    const Csc G(A);
    const int* outer = F.A.outerIndexPtr();
    double* val = F.A.valuePtr();
    for_rows(F.n(), [&](int b, int e) {
      for (int r = b; r < e; ++r) {
        const int j = old_index(F.perm, r);
        std::copy(G.val + G.outer[j], G.val + G.outer[j + 1], val + outer[r]);
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
    }
    ++numeric_builds;
    return ok;
  }

  // ---- cycle ----

  void sweep(int l, bool reverse) {
    Level& L = levels[std::size_t(l)];
    const Csc A(L.A);
    const std::size_t s = std::size_t(k);
    const double* id = L.inv_diag.data();
    const int* dp = L.diag_pos.data();
    const double* b = L.b.data();
    double* x = L.x.data();
    for_column_chunks(k, [&](auto KC, int o) {
      constexpr int K = decltype(KC)::value;
      if (L.coloured) {
        for (int ci = 0; ci < 8; ++ci) {
          const int c = reverse ? 7 - ci : ci;
          const int tiles = int(L.segment_start.size() / 8);
          const auto relax_tiles = [&](int t0, int t1) {
            for (int t = t0; t < t1; ++t) {
              const std::size_t q = std::size_t(t) * 8 + std::size_t(c);
              for (int r = L.segment_start[q]; r < L.segment_start[q + 1]; ++r) gs_row<K>(A, dp, id, b, x, s, o, r);
            }
          };
          if (tiles == 1) {
            relax_tiles(0, 1);
          } else {
            tbb::parallel_for(tbb::blocked_range<int>(0, tiles, 1),
                              [&](const tbb::blocked_range<int>& r) { relax_tiles(r.begin(), r.end()); });
          }
        }
      } else if (!reverse) {
        for (int i = 0; i < A.cols; ++i) gs_row<K>(A, dp, id, b, x, s, o, i);
      } else {
        for (int i = A.cols - 1; i >= 0; --i) gs_row<K>(A, dp, id, b, x, s, o, i);
      }
    });
  }

  void residual(int l) {
    Level& L = levels[std::size_t(l)];
    const Csc A(L.A);
    const std::size_t s = std::size_t(k);
    for_column_chunks(k, [&](auto KC, int o) {
      constexpr int K = decltype(KC)::value;
      for_rows(A.cols, [&](int b, int e) { residual_rows<K>(A, L.b.data(), L.x.data(), L.r.data(), s, o, b, e); });
    });
  }

  void coarse_solve() {
    Level& L = levels.front();
    const int n = L.n();
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < k; ++c) coarse_rhs(i, c) = L.b[std::size_t(i) * std::size_t(k) + std::size_t(c)];
    coarse_sol = ldlt.solve(coarse_rhs);
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < k; ++c) L.x[std::size_t(i) * std::size_t(k) + std::size_t(c)] = coarse_sol(i, c);
  }

  // Two clock reads per level visit (a W-cycle at depth 9 makes 384): noise next to the sweeps.
  using Clock = std::chrono::steady_clock;
  static double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

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
    const std::size_t s = std::size_t(k);
    for (int i = 0; i < opt.pre_smooth; ++i) sweep(l, false);
    residual(l);
    // Restriction: b_C = Pᵀ r_F (gather over the columns of P).
    const Csc P(C.P), PT(C.PT);
    for_column_chunks(k, [&](auto KC, int o) {
      constexpr int K = decltype(KC)::value;
      for_rows(P.cols, [&](int b, int e) { transpose_rows<K, false>(P, F.r.data(), C.b.data(), s, o, b, e); });
    });
    std::fill(C.x.begin(), C.x.end(), 0.0);
    // γ = 2 for W; an exact coarsest solve is never repeated (it would change nothing).
    const int gamma = (opt.cycle == MultigridCycle::W && l - 1 > 0) ? 2 : 1;
    const auto tc = Clock::now();
    for (int g = 0; g < gamma; ++g) cycle(l - 1, opt);
    const double coarser = since(tc);  // the recursion's time, not this level's own
    // Prolongation: x_F += P x_C (gather over the columns of Pᵀ = rows of P).
    for_column_chunks(k, [&](auto KC, int o) {
      constexpr int K = decltype(KC)::value;
      for_rows(PT.cols, [&](int b, int e) { transpose_rows<K, true>(PT, C.x.data(), F.x.data(), s, o, b, e); });
    });
    for (int i = 0; i < opt.post_smooth; ++i) sweep(l, true);
    w.seconds += since(t0) - coarser;
  }

  /// max over columns of ||b - A x|| / ||b|| on the finest level (deterministic reduction).
  double relative_residual(const Eigen::VectorXd& bnorm) {
    Level& L = levels.back();
    const Csc A(L.A);
    const std::size_t s = std::size_t(k);
    std::vector<double> rn(std::size_t(k), 0.0);
    for_column_chunks(k, [&](auto KC, int o) {
      constexpr int K = decltype(KC)::value;
      using Acc = std::array<double, K>;
      const Acc sum = tbb::parallel_deterministic_reduce(
          tbb::blocked_range<int>(0, A.cols, 4096), Acc{},
          [&](const tbb::blocked_range<int>& r, Acc acc) {
            for (int i = r.begin(); i < r.end(); ++i) {
              double res[K];
              const std::size_t ii = std::size_t(i) * s + o;
              for (int c = 0; c < K; ++c) res[c] = L.b[ii + c];
              for (int p = A.outer[i]; p < A.outer[i + 1]; ++p) {
                const double a = A.val[p];
                const double* xj = L.x.data() + std::size_t(A.inner[p]) * s + o;
                for (int c = 0; c < K; ++c) res[c] -= a * xj[c];
              }
              for (int c = 0; c < K; ++c) acc[std::size_t(c)] += res[c] * res[c];
            }
            return acc;
          },
          [](Acc a, const Acc& b) {
            for (int c = 0; c < K; ++c) a[std::size_t(c)] += b[std::size_t(c)];
            return a;
          });
      for (int c = 0; c < K; ++c) rn[std::size_t(o + c)] = sum[std::size_t(c)];
    });
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
  void load(const Level& L, std::vector<double>& dst, const Eigen::MatrixXd& src) {
    const std::size_t s = std::size_t(k);
    for_rows(int(src.rows()), [&](int b, int e) {
      for (int r = b; r < e; ++r) {
        const int i = old_index(L.perm, r);
        for (int c = 0; c < k; ++c) dst[std::size_t(r) * s + std::size_t(c)] = src(i, c);
      }
    });
  }
  void store(const Level& L, const std::vector<double>& src, Eigen::MatrixXd& dst) {
    const std::size_t s = std::size_t(k);
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

int MultigridSolver::levels() const { return impl_->ready ? int(impl_->levels.size()) : 0; }
SparseMatrix MultigridSolver::level_matrix(int l) const {
  const auto& L = impl_->levels.at(std::size_t(l));
  return permuted(L.A, L.perm, L.inv, true);  // back to the caller's numbering
}
bool MultigridSolver::level_is_coloured(int l) const { return impl_->levels.at(std::size_t(l)).coloured; }
std::int64_t MultigridSolver::symbolic_builds() const { return impl_->symbolic_builds; }
std::int64_t MultigridSolver::numeric_builds() const { return impl_->numeric_builds; }
std::int64_t MultigridSolver::pattern_comparisons() const { return impl_->pattern_comparisons; }
std::vector<MultigridLevelWork> MultigridSolver::level_work() const { return impl_->work; }
void MultigridSolver::reset_level_work() {
  for (auto& w : impl_->work) w = MultigridLevelWork{};
}

SolveReport MultigridSolver::set_matrix(const SparseMatrix& A_in, HierarchyView hierarchy) {
  SolveReport rep;
  Impl& m = *impl_;
  m.ready = false;
  auto fail = [&](SolveStatus st, std::string msg) {
    rep.status = st;
    rep.message = std::move(msg);
    return rep;
  };
  if (A_in.rows() != A_in.cols() || A_in.rows() == 0) return fail(SolveStatus::failed, "matrix is not square or empty");
  SparseMatrix compressed;
  const SparseMatrix* Ap = &A_in;
  if (!A_in.isCompressed()) {
    compressed = A_in;
    compressed.makeCompressed();
    Ap = &compressed;
  }
  const SparseMatrix& A = *Ap;

  static const std::vector<SparseMatrix> kNone;
  const std::vector<SparseMatrix>& P = hierarchy.empty() ? kNone : *hierarchy.prolongations;
  const auto* colours = hierarchy.colours;
  // Dimensions: P[l] maps level l to l+1; the last one maps onto A's level.
  Eigen::Index fine = A.rows();
  for (std::size_t l = P.size(); l-- > 0;) {
    if (P[l].rows() != fine || P[l].cols() <= 0)
      return fail(SolveStatus::failed, "prolongation " + std::to_string(l) + " has wrong dimensions");
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
      need_symbolic = !same_permuted(F.A, A, F.inv, F.perm, false, false);
    }
    for (std::size_t l = 0; !need_symbolic && l < P.size(); ++l)
      need_symbolic =
          !same_permuted(m.levels[l].P, P[l], m.levels[l + 1].inv, m.levels[l].perm, true, true);
  }
  if (need_symbolic) {
    m.symbolic(A, P, colours);
  } else {
    m.set_fine_values(A);
  }
  m.pattern_key = key;
  const bool diag_ok = m.numeric();

  if (need_symbolic) m.ldlt.analyzePattern(m.levels.front().A);
  m.ldlt.factorize(m.levels.front().A);
  if (!diag_ok) return fail(SolveStatus::not_positive_definite, "negative or non-finite diagonal entry");
  if (m.ldlt.info() != Eigen::Success)
    return fail(SolveStatus::not_positive_definite, "coarsest-level factorization failed");
  const Eigen::VectorXd D = m.ldlt.vectorD();
  if (D.size() > 0 && !(D.minCoeff() > 0.0))
    return fail(SolveStatus::not_positive_definite, "coarsest-level matrix is not positive definite");
  for (std::size_t l = 1; l < m.levels.size(); ++l)
    if (!m.levels[l].coloured)
      rep.message += (rep.message.empty() ? "" : "; ") + std::string("level ") + std::to_string(l) +
                     " uses serial Gauss-Seidel (no valid colouring)";
  m.ready = true;
  rep.iterations = 0;
  return rep;
}

SolveReport MultigridSolver::solve(const Eigen::MatrixXd& B, Eigen::MatrixXd& X) {
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
  if (X.rows() != n || X.cols() != k) X.setZero(n, k);
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
