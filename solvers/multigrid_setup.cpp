#include "solvers/multigrid_state.h"

#include "core/galerkin_pattern.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>

namespace mcf::multigrid_detail {

void MultigridState::symbolic(const SparseRef& A, const std::vector<SparseMatrix>& P,
                              const std::vector<std::vector<std::uint8_t>>* given_colours,
                              bool single) {
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
    C.A = galerkin_pattern(C.P, levels[l + 1].A);  // pattern of Pᵀ A P, sorted
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

template <class Put>
void MultigridState::walk_fine(const Csc& G, double* val, const Put& put) {
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

void MultigridState::set_fine_values(const SparseRef& A, const MatrixSum* sum) {
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

void MultigridState::set_fine_terms(const MatrixSum& sum, bool fresh) {
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

// Laying a plan out costs about two products, which a pattern used once (the rebuilt octree's,
// new every step) would not earn back: it is built when the level's product is computed a second
// time on its pattern, or at once when the caller vouches for its pattern with a key (it owns a
// fixed pattern and will set it again), so that the flow's second step is a steady one.
const GalerkinPlan* MultigridState::plan_for(std::size_t l) {
  Level& C = levels[l];
  if (++C.galerkin_calls == (pattern_key != 0 ? 1 : 2))
    C.plan = galerkin_plan(Csc(levels[l + 1].A), C.P, C.A, C.inv);
  return &C.plan;
}

void MultigridState::drop_terms() {
  term_count = 0;
  term_changed.clear();
  for (auto& L : levels) L.terms.clear();
}

void MultigridState::coarse_by_term(std::size_t l, const MatrixSum& sum) {
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

bool MultigridState::numeric(const MatrixSum* by_term, bool coarse) {
  for (std::size_t l = levels.size() - 1; coarse && l-- > 0;) {
    Level& C = levels[l];
    if (by_term)
      coarse_by_term(l, *by_term);
    else
      galerkin_values(Csc(levels[l + 1].A), C.P, C.A, C.A.valuePtr(), C.transpose_pos, C.inv, C.spa,
                      plan_for(l));
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

bool MultigridState::coarsest_factor_is_sound() const {
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

std::string MultigridState::coarsest_pseudo_inverse(int& null_dimension) {
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

SolveReport MultigridState::set_up(const SparseRef& A_in, const MatrixSum* sum,
                                   HierarchyView hierarchy, const MultigridOptions& options) {
  SolveReport rep;
  const bool was_ready = ready;
  ready = false;
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
  const auto* given_colours = hierarchy.colours;
  // Dimensions: P[l] maps level l to l+1; the last one maps onto A's level.
  Eigen::Index fine = A.rows();
  for (std::size_t l = P.size(); l-- > 0;) {
    if (P[l].rows() != fine || P[l].cols() <= 0)
      return fail(SolveStatus::failed,
                  "prolongation " + std::to_string(l) + " has wrong dimensions");
    fine = P[l].cols();
  }

  const std::uint64_t key = hierarchy.pattern_key;
  const bool vouched = key != 0 && key == pattern_key;
  pattern_key = 0;  // until this call has set up levels for the given pattern
  // The O(1) checks run even when vouched for: a wrong key must not make set_fine_values write
  // past the stored pattern.
  bool need_symbolic = levels.size() != P.size() + 1 || levels.back().n() != A.rows() ||
                       levels.back().A.nonZeros() != A.nonZeros();
  if (!need_symbolic && !vouched) {
    ++pattern_comparisons;
    const std::size_t nc = given_colours ? given_colours->size() : 0;
    need_symbolic = nc != colours.size() || (nc > 0 && *given_colours != colours);
    if (!need_symbolic) {
      const auto& F = levels.back();
      need_symbolic = !same_permuted(F.A, A, F.inv, F.perm, false, false, F.diag_rank);
    }
    for (std::size_t l = 0; !need_symbolic && l < P.size(); ++l)
      need_symbolic =
          !same_permuted(levels[l].P, P[l], levels[l + 1].inv, levels[l].perm, true, true);
  }
  // symbolic() copies A's values along with its pattern; a sum overwrites them.
  // A vouched-for pattern is still set up anew when the finest sweeps' precision changed.
  if (!need_symbolic && fine_single != options.mixed_precision) need_symbolic = true;
  if (need_symbolic) symbolic(A, P, given_colours, options.mixed_precision);
  if (!need_symbolic || sum) set_fine_values(A, sum);
  ++calls;
  const bool by_term = options.galerkin_by_term && sum != nullptr && levels.size() > 1;
  if (by_term)
    set_fine_terms(*sum, need_symbolic);
  else
    drop_terms();
  pattern_key = key;
  // galerkin_refresh: keep the coarse operators of an earlier successful call on this pattern.
  // `ready` was true before this call exactly when that call succeeded (it is reset above).
  const bool lagged = !need_symbolic && !by_term && levels.size() > 1 && was_ready &&
                      options.galerkin_refresh > 1 &&
                      calls_since_refresh + 1 < options.galerkin_refresh;
  const bool diag_ok = numeric(by_term ? sum : nullptr, !lagged);
  if (lagged) {
    ++calls_since_refresh;
    ++lagged_refreshes;
  } else {
    calls_since_refresh = 0;
    if (need_symbolic) ldlt.analyzePattern(levels.front().A);
    ldlt.factorize(levels.front().A);
  }
  if (!diag_ok)
    return fail(SolveStatus::not_positive_definite, "negative or non-finite diagonal entry");
  if (!lagged) {
    // The coarse levels' notes, which a lagged call repeats with their operators.
    coarse_note.clear();
    coarse_pinv.resize(0, 0);
    if (coarsest_factor_is_sound())
      copy_factor(ldlt, coarse_factor);
    else {
      // The octree's functions on a flat face parallel to a grid plane (the cubical spiral, a
      // box) are linearly dependent on the surface: A is then only semi-definite, on every
      // level. Gauss–Seidel relaxes such a consistent system as it does a definite one (the
      // paper's solver never factors the fine matrix); the coarsest level needs a generalized
      // inverse.
      int null_dimension = 0;
      const std::string why = coarsest_pseudo_inverse(null_dimension);
      if (!why.empty()) return fail(SolveStatus::not_positive_definite, why);
      coarse_note = "coarsest level semi-definite (null space of dimension " +
                    std::to_string(null_dimension) + "): solved by its pseudo-inverse";
    }
    for (std::size_t l = 1; l < levels.size(); ++l)
      if (!levels[l].coloured)
        coarse_note += (coarse_note.empty() ? "" : "; ") + std::string("level ") +
                       std::to_string(l) + " has no valid colouring: relaxed in blocks of rows";
  }
  rep.message = coarse_note;
  ready = true;
  rep.iterations = 0;
  return rep;
}

}  // namespace mcf::multigrid_detail
