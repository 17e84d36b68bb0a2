#include "solvers/smoother.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdint>
#include <utility>

namespace mcf::multigrid_detail {

std::vector<int> diagonal_positions(const SparseMatrix& Am) {
  const Csc A(Am);
  const int n = A.rows;
  std::vector<int> diag_pos(std::size_t(n), -1);
  for_rows(n, [&](int b, int e) {
    for (int i = b; i < e; ++i)
      for (int p = A.outer[i]; p < A.outer[i + 1]; ++p)
        if (A.inner[p] == i) {
          diag_pos[std::size_t(i)] = p;
          break;
        }
  });
  return diag_pos;
}

std::vector<int> diagonal_last(SparseMatrix& A) {
  const int n = int(A.rows());
  int* outer = A.outerIndexPtr();
  int* inner = A.innerIndexPtr();
  double* val = A.valuePtr();
  std::vector<int> diag_rank(std::size_t(n), -1);
  for_rows(n, [&](int b, int e) {
    for (int r = b; r < e; ++r) {
      const int p0 = outer[r], p1 = outer[r + 1];
      const int* d = std::find(inner + p0, inner + p1, r);
      if (d == inner + p1) continue;
      const int k = int(d - (inner + p0));
      diag_rank[std::size_t(r)] = k;
      std::rotate(inner + p0 + k, inner + p0 + k + 1, inner + p1);
      std::rotate(val + p0 + k, val + p0 + k + 1, val + p1);
    }
  });
  return diag_rank;
}

SmootherRows smoother_pattern(const SparseMatrix& Am, const std::vector<int>& diag_pos,
                              bool finest) {
  SmootherRows S;
  const Csc A(Am);
  const int n = A.rows;
  const auto fits16 = [](int d) { return d >= INT16_MIN && d <= INT16_MAX; };
  if (finest) {
    std::vector<std::int16_t> offset(std::size_t(A.outer[A.cols]));
    for (int i = 0; i < n; ++i)
      for (int p = A.outer[i]; p < A.outer[i + 1]; ++p) {
        const int d = A.inner[p] - i;
        if (!fits16(d)) return SmootherRows{};
        offset[std::size_t(p)] = std::int16_t(d);
      }
    S.offset = std::move(offset);
    S.aligned = true;
    return S;
  }
  std::vector<int> start(std::size_t(n) + 1, 0);
  for (int i = 0; i < n; ++i) {
    const int dp = diag_pos[std::size_t(i)];
    start[std::size_t(i) + 1] =
        start[std::size_t(i)] + (A.outer[i + 1] - A.outer[i]) - (dp >= 0 ? 1 : 0);
  }
  std::vector<std::int16_t> offset(std::size_t(start.back()));
  for (int i = 0; i < n; ++i) {
    int e = start[std::size_t(i)];
    for (int p = A.outer[i]; p < A.outer[i + 1]; ++p) {
      const int d = A.inner[p] - i;
      if (d == 0) continue;
      if (!fits16(d)) return SmootherRows{};
      offset[std::size_t(e++)] = std::int16_t(d);
    }
  }
  S.start = std::move(start);
  S.offset = std::move(offset);
  S.single.assign(S.offset.size(), 0.0f);
  return S;
}

void smoother_values(SmootherRows& S, const SparseMatrix& Am, const std::vector<int>& diag_pos) {
  if (S.empty() || S.aligned) return;
  const Csc A(Am);
  // A row's off-diagonal entries are the runs before and after its diagonal (diag_pos), so they
  // are copied as two runs without reading the row indices.
  float* out = S.single.data();
  for_rows(A.rows, [&](int b, int e) {
    for (int i = b; i < e; ++i) {
      const int p0 = A.outer[i], p1 = A.outer[i + 1], dp = diag_pos[std::size_t(i)];
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

namespace {

/// A sweep's two passes over relaxation blocks (header, "Smoother ordering"): the blocks of one
/// parity (parity, parity + 2, ...) never couple, so each pass relaxes them in parallel.
template <class Relax>
void relax_by_parity(int blocks, bool reverse, const Relax& relax_block) {
  for (int pi = 0; pi < 2; ++pi) {
    const int parity = block_parity(pi, reverse);
    const int count = (blocks - parity + 1) / 2;
    if (count <= 1) {
      for (int j = 0; j < count; ++j) relax_block(parity + 2 * j);
      continue;
    }
    tbb::parallel_for(tbb::blocked_range<int>(0, count, 1), [&](const tbb::blocked_range<int>& r) {
      for (int j = r.begin(); j < r.end(); ++j) relax_block(parity + 2 * j);
    });
  }
}

}  // namespace

void gauss_seidel_sweep(const LevelNumbering& L, const Csc& A, const SmootherRows& S,
                        const int* diag_pos, const double* inv_diag, const double* b, double* x,
                        std::size_t s, bool reverse) {
  const int* dp = diag_pos;
  const double* id = inv_diag;
  for (int o = 0; o < int(s); o += 4) {
    if (L.coloured) {
      const auto relax_block = [&](int q) {
        for_block_segments(L, q, reverse, [&](int r0, int r1) {
          if (S.aligned) {
            for (int r = r0; r < r1; ++r) gs_row_aligned(A, S.offset.data(), dp, id, b, x, s, o, r);
          } else if (!S.empty()) {
            for (int r = r0; r < r1; ++r) gs_row_compact(S, S.single.data(), id, b, x, s, o, r);
          } else {
            for (int r = r0; r < r1; ++r) gs_row(A, dp, id, b, x, s, o, r);
          }
        });
      };
      relax_by_parity(L.blocks(), reverse, relax_block);
    } else {
      // Without colours: blocks of consecutive rows, each relaxed in row order (reverse: the
      // exact reverse), even blocks in parallel, then odd ones (header, "Smoother ordering").
      const auto relax_block = [&](int q) {
        const int first = L.block_first(q), last = L.block_last(q);
        // Written out per kernel and direction: a generic row lambda here measured a few
        // percent slower.
        if (!S.empty()) {
          if (!reverse)
            for (int i = first; i < last; ++i)
              gs_row_compact(S, S.single.data(), id, b, x, s, o, i);
          else
            for (int i = last - 1; i >= first; --i)
              gs_row_compact(S, S.single.data(), id, b, x, s, o, i);
        } else if (!reverse) {
          for (int i = first; i < last; ++i) gs_row(A, dp, id, b, x, s, o, i);
        } else {
          for (int i = last - 1; i >= first; --i) gs_row(A, dp, id, b, x, s, o, i);
        }
      };
      relax_by_parity(L.blocks(), reverse, relax_block);
    }
  }
}

}  // namespace mcf::multigrid_detail
