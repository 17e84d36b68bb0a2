#include "solvers/level_ordering.h"

#include "solvers/csc_view.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <cstdlib>
#include <utility>

namespace mcf::multigrid_detail {

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

bool same_permuted(const SparseMatrix& stored, const SparseRef& given,
                   const std::vector<int>& row_inv, const std::vector<int>& col_perm, bool sort,
                   bool values, const std::vector<int>& diag_rank) {
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

void number_by_colour(LevelNumbering& L, int n, const std::vector<std::uint8_t>* given) {
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

void check_colouring(LevelNumbering& L, const SparseMatrix& Am,
                     const std::vector<std::uint8_t>* given) {
  L.coloured = false;
  if (L.perm.empty()) return;
  const auto colour = [&](int r) { return (*given)[std::size_t(L.perm[std::size_t(r)])]; };
  const Csc A(Am);
  const bool ok = tbb::parallel_reduce(
      tbb::blocked_range<int>(0, A.rows, 4096), true,
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

void find_blocks(LevelNumbering& L, const SparseMatrix& Am) {
  L.block_tiles = 1;
  const Csc A(Am);
  L.rows = A.rows;
  // The farthest coupling, in tiles (coloured) or in rows (not).
  const int unit = L.coloured ? kTile : 1;
  const int reach = tbb::parallel_reduce(
      tbb::blocked_range<int>(0, A.rows, 4096), 0,
      [&](const tbb::blocked_range<int>& rows, int far) {
        for (int r = rows.begin(); r < rows.end(); ++r)
          for (int p = A.outer[r]; p < A.outer[r + 1]; ++p)
            far = std::max(far, std::abs(A.inner[p] / unit - r / unit));
        return far;
      },
      [](int a, int b) { return std::max(a, b); });
  if (L.coloured)
    L.block_tiles = std::max(reach, kMinBlockTiles);
  else
    L.block_rows = std::max(reach, kMinBlockTiles * kTile);
}

std::vector<int> relaxation_order(const LevelNumbering& L, int n, bool reverse) {
  std::vector<int> order;
  order.reserve(std::size_t(n));
  if (L.coloured) {
    for (int pi = 0; pi < 2; ++pi)
      for (int q = block_parity(pi, reverse); q < L.blocks(); q += 2)
        for_block_segments(L, q, reverse, [&](int r0, int r1) {
          for (int r = r0; r < r1; ++r) order.push_back(old_index(L.perm, r));
        });
  } else {
    for (int pi = 0; pi < 2; ++pi)
      for (int q = block_parity(pi, reverse); q < L.blocks(); q += 2)
        for (int r = L.block_first(q); r < L.block_last(q); ++r)
          order.push_back(
              old_index(L.perm, reverse ? L.block_first(q) + L.block_last(q) - 1 - r : r));
  }
  return order;
}

}  // namespace mcf::multigrid_detail
