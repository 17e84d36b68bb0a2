#include "solvers/interleaved_ldlt.h"

#include "core/vec4.h"

namespace mcf::multigrid_detail {

using vec4::load4;
using vec4::splat;
using vec4::store4;
using vec4::v4;

void copy_factor(const Eigen::SimplicialLDLT<SparseMatrix>& ldlt, InterleavedLdlt& f) {
  const SparseMatrix& L = ldlt.matrixL().nestedExpression();  // strictly lower, unit diagonal
  const int n = int(L.cols());
  f.outer.assign(L.outerIndexPtr(), L.outerIndexPtr() + n + 1);
  // Compressed (SimplicialLDLT keeps L so): the columns are contiguous.
  f.inner.assign(L.innerIndexPtr() + f.outer.front(), L.innerIndexPtr() + f.outer.back());
  f.val.assign(L.valuePtr() + f.outer.front(), L.valuePtr() + f.outer.back());
  for (int& p : f.outer) p -= L.outerIndexPtr()[0];
  // Lᵀ in compressed columns (L's rows): a counting transpose, each column's rows ascending.
  f.upper_outer.assign(std::size_t(n) + 1, 0);
  for (const int i : f.inner) ++f.upper_outer[std::size_t(i) + 1];
  for (int i = 0; i < n; ++i) f.upper_outer[std::size_t(i) + 1] += f.upper_outer[std::size_t(i)];
  f.upper_inner.resize(f.inner.size());
  f.upper_val.resize(f.val.size());
  std::vector<int>& next = f.next;
  next.assign(f.upper_outer.begin(), f.upper_outer.end() - 1);
  for (int j = 0; j < n; ++j)
    for (int p = f.outer[std::size_t(j)]; p < f.outer[std::size_t(j) + 1]; ++p) {
      const int q = next[std::size_t(f.inner[std::size_t(p)])]++;
      f.upper_inner[std::size_t(q)] = j;
      f.upper_val[std::size_t(q)] = f.val[std::size_t(p)];
    }
  // Eigen applies D⁻¹ as a product with the reciprocals.
  f.inverse_diagonal.resize(std::size_t(n));
  for (int i = 0; i < n; ++i) f.inverse_diagonal[std::size_t(i)] = 1.0 / ldlt.vectorD()[i];
  const auto& P = ldlt.permutationP().indices();
  f.perm.resize(std::size_t(n));
  for (int i = 0; i < n; ++i) f.perm[std::size_t(i)] = P.size() > 0 ? P[i] : i;  // none: natural
}

namespace {

/// first - Σ_p val[p] w_inner[p] over column j's entries, four columns of w at once. The sum runs
/// in four partial sums taking the entries in turn, so that four multiply-adds are in flight
/// instead of one chain of dependent ones.
inline v4 dot_sub(const std::vector<int>& outer, const std::vector<int>& inner,
                  const std::vector<double>& val, int j, const double* w, v4 first) {
  v4 acc[4] = {first, splat(0.0), splat(0.0), splat(0.0)};
  int p = outer[std::size_t(j)];
  const int end = outer[std::size_t(j) + 1];
  for (; p + 3 < end; p += 4)
    for (int a = 0; a < 4; ++a)
      acc[a] -=
          splat(val[std::size_t(p + a)]) * load4(w + std::size_t(inner[std::size_t(p + a)]) * 4);
  for (int a = 0; p < end; ++p, ++a)
    acc[a] -= splat(val[std::size_t(p)]) * load4(w + std::size_t(inner[std::size_t(p)]) * 4);
  return (acc[0] + acc[1]) + (acc[2] + acc[3]);
}

}  // namespace

void solve_interleaved(const InterleavedLdlt& f, const double* b, double* x, std::size_t s,
                       std::vector<double>& work) {
  const int n = f.n();
  work.resize(std::size_t(n) * 4);
  double* w = work.data();
  const auto at = [w](int i) { return w + std::size_t(i) * 4; };
  for (std::size_t o = 0; o < s; o += 4) {
    for (int i = 0; i < n; ++i)
      store4(at(f.perm[std::size_t(i)]), load4(b + std::size_t(i) * s + o));
    // L y = P b row by row (a column of Lᵀ): y_i = w_i - Σ_j L_ij y_j over the rows solved before
    // it; Lᵀ z = D⁻¹ y row by row of Lᵀ (a column of L): z_j = y_j / D_j - Σ_i L_ij z_i over the
    // rows solved after it. Both are dot products, with no store per entry.
    for (int i = 0; i < n; ++i)
      store4(at(i), dot_sub(f.upper_outer, f.upper_inner, f.upper_val, i, w, load4(at(i))));
    for (int j = n - 1; j >= 0; --j)
      store4(at(j), dot_sub(f.outer, f.inner, f.val, j, w,
                            load4(at(j)) * splat(f.inverse_diagonal[std::size_t(j)])));
    for (int i = 0; i < n; ++i)
      store4(x + std::size_t(i) * s + o, load4(at(f.perm[std::size_t(i)])));
  }
}

}  // namespace mcf::multigrid_detail
