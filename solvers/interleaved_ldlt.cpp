#include "solvers/interleaved_ldlt.h"

#include "core/vec4.h"
#include "solvers/csc_view.h"

namespace mcf::multigrid_detail {

using vec4::load4;
using vec4::splat;
using vec4::store4;
using vec4::v4;

void copy_factor(const Eigen::SimplicialLDLT<SparseMatrix>& ldlt, InterleavedLdlt& f) {
  f.lower = ldlt.matrixL().nestedExpression();  // strictly lower, unit diagonal implicit
  f.lower.makeCompressed();  // (a no-op: Eigen keeps L compressed) the solve reads raw arrays
  f.upper = f.lower.transpose();
  f.upper.makeCompressed();
  const int n = int(f.lower.cols());
  // Eigen applies D⁻¹ as a product with the reciprocals.
  f.inverse_diagonal.resize(std::size_t(n));
  for (int i = 0; i < n; ++i) f.inverse_diagonal[std::size_t(i)] = 1.0 / ldlt.vectorD()[i];
  const auto& P = ldlt.permutationP().indices();
  f.perm.resize(std::size_t(n));
  for (int i = 0; i < n; ++i) f.perm[std::size_t(i)] = P.size() > 0 ? P[i] : i;  // none: natural
}

namespace {

/// first - Σ_p val[p] w_inner[p] over column j's entries of M, four columns of w at once. The sum
/// runs in four partial sums taking the entries in turn, so that four multiply-adds are in flight
/// instead of one chain of dependent ones.
inline v4 dot_sub(const Csc& M, int j, const double* w, v4 first) {
  v4 acc[4] = {first, splat(0.0), splat(0.0), splat(0.0)};
  int p = M.outer[j];
  const int end = M.outer[j + 1];
  for (; p + 3 < end; p += 4)
    for (int a = 0; a < 4; ++a)
      acc[a] -= splat(M.val[p + a]) * load4(w + std::size_t(M.inner[p + a]) * 4);
  for (int a = 0; p < end; ++p, ++a)
    acc[a] -= splat(M.val[p]) * load4(w + std::size_t(M.inner[p]) * 4);
  return (acc[0] + acc[1]) + (acc[2] + acc[3]);
}

}  // namespace

void solve_interleaved(const InterleavedLdlt& f, const double* b, double* x, std::size_t s,
                       std::vector<double>& work) {
  const int n = f.n();
  work.resize(std::size_t(n) * 4);
  double* w = work.data();
  const auto at = [w](int i) { return w + std::size_t(i) * 4; };
  const Csc lower(f.lower), upper(f.upper);
  for (std::size_t o = 0; o < s; o += 4) {
    for (int i = 0; i < n; ++i)
      store4(at(f.perm[std::size_t(i)]), load4(b + std::size_t(i) * s + o));
    // L y = P b row by row (a column of Lᵀ): y_i = w_i - Σ_j L_ij y_j over the rows solved before
    // it; Lᵀ z = D⁻¹ y row by row of Lᵀ (a column of L): z_j = y_j / D_j - Σ_i L_ij z_i over the
    // rows solved after it. Both are dot products, with no store per entry.
    for (int i = 0; i < n; ++i) store4(at(i), dot_sub(upper, i, w, load4(at(i))));
    for (int j = n - 1; j >= 0; --j)
      store4(at(j), dot_sub(lower, j, w, load4(at(j)) * splat(f.inverse_diagonal[std::size_t(j)])));
    for (int i = 0; i < n; ++i)
      store4(x + std::size_t(i) * s + o, load4(at(f.perm[std::size_t(i)])));
  }
}

}  // namespace mcf::multigrid_detail
