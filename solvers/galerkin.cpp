#include "solvers/galerkin.h"

#include "solvers/csc_view.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstddef>

namespace mcf::multigrid_detail {

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

std::vector<int> transpose_positions(const SparseMatrix& C) {
  const Csc M(C);
  std::vector<int> transpose_pos(std::size_t(C.nonZeros()), -1);
  tbb::parallel_for(0, M.cols, [&](int J) {
    for (int e = M.outer[J]; e < M.outer[J + 1]; ++e) {
      const int i = M.inner[e];
      const int* b = M.inner + M.outer[i];
      const int* en = M.inner + M.outer[i + 1];
      const int* it = std::lower_bound(b, en, J);
      if (it != en && *it == J) transpose_pos[std::size_t(e)] = int(it - M.inner);
    }
  });
  return transpose_pos;
}

void galerkin_values(const Csc& A, const SparseMatrix& Pm, const SparseMatrix& Cm, double* Cval,
                     const std::vector<int>& transpose_pos, const std::vector<int>& column_order,
                     Spa& spa) {
  const Csc P(Pm);
  const int m = A.rows;
  const int* Couter = Cm.outerIndexPtr();
  const int* Cinner = Cm.innerIndexPtr();
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

}  // namespace mcf::multigrid_detail
