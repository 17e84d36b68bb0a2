#include "solvers/smoother.h"

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

}  // namespace mcf::multigrid_detail
