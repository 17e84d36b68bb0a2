#include "core/galerkin_pattern.h"

#include "core/compressed_sets.h"

#include <algorithm>
#include <cstddef>
#include <vector>

namespace mcf {

SparseMatrix galerkin_pattern(const SparseMatrix& P, const SparseMatrix& A) {
  const int n = int(P.rows()), nc = int(P.cols());
  const int* Pouter = P.outerIndexPtr();
  const int* Pinner = P.innerIndexPtr();
  const int* Aouter = A.outerIndexPtr();
  const int* Ainner = A.innerIndexPtr();
  // P's rows: the coarse functions each fine function takes values from (ascending).
  std::vector<int> row_start(std::size_t(n) + 1, 0), row_coarse(std::size_t(P.nonZeros()));
  for (int p = 0; p < Pouter[nc]; ++p) ++row_start[std::size_t(Pinner[p]) + 1];
  for (int i = 0; i < n; ++i) row_start[std::size_t(i) + 1] += row_start[std::size_t(i)];
  {
    std::vector<int> fill(row_start.begin(), row_start.end() - 1);
    for (int J = 0; J < nc; ++J)
      for (int p = Pouter[J]; p < Pouter[J + 1]; ++p)
        row_coarse[std::size_t(fill[std::size_t(Pinner[p])]++)] = J;
  }
  int longest_row = 0;
  for (int i = 0; i < n; ++i)
    longest_row = std::max(longest_row, row_start[std::size_t(i) + 1] - row_start[std::size_t(i)]);
  // Two set products, as the numeric product takes them: first the coarse functions next to each
  // fine one (the pattern of P^T A, column j: every I with P(i, I) A(i, j) stored), then column J
  // of the product: the union of those sets over the fine functions of P's column J. Taking the
  // union per fine function first does each repeated I once. (Members are written whether new or
  // not and kept by the count: no branch on the mark.)
  std::vector<int> near_start, near;
  gather_sets(
      n, nc, [&](int j) { return (Aouter[j + 1] - Aouter[j]) * longest_row; },
      [&](int j, int* mark, int* out) {
        int count = 0;
        for (int a = Aouter[j]; a < Aouter[j + 1]; ++a) {
          const int i = Ainner[a];
          for (int r = row_start[std::size_t(i)]; r < row_start[std::size_t(i) + 1]; ++r) {
            const int I = row_coarse[std::size_t(r)];
            out[count] = I;
            count += mark[I] != j;
            mark[I] = j;
          }
        }
        return count;
      },
      near_start, near);
  int most_near = 0;
  for (int j = 0; j < n; ++j)
    most_near = std::max(most_near, near_start[std::size_t(j) + 1] - near_start[std::size_t(j)]);
  std::vector<int> outer, inner;
  gather_sets(
      nc, nc, [&](int J) { return (Pouter[J + 1] - Pouter[J]) * most_near; },
      [&](int J, int* mark, int* out) {
        int count = 0;
        for (int p = Pouter[J]; p < Pouter[J + 1]; ++p) {
          const int j = Pinner[p];
          for (int r = near_start[std::size_t(j)]; r < near_start[std::size_t(j) + 1]; ++r) {
            const int I = near[std::size_t(r)];
            out[count] = I;
            count += mark[I] != J;
            mark[I] = J;
          }
        }
        return count;
      },
      outer, inner);
  // The product is symmetric (A is), so its transpose sorts it.
  sort_symmetric_sets(outer, inner);
  SparseMatrix C(nc, nc);
  C.resizeNonZeros(Eigen::Index(inner.size()));
  std::copy(outer.begin(), outer.end(), C.outerIndexPtr());
  std::copy(inner.begin(), inner.end(), C.innerIndexPtr());
  std::fill(C.valuePtr(), C.valuePtr() + C.nonZeros(), 0.0);
  return C;
}

}  // namespace mcf
