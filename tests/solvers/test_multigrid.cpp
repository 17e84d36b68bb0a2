// MultigridSolver on synthetic grid problems: a regular 3D grid of trilinear functions
// (depth d: (2^d+1)^3 functions), A = M + dt K of the trilinear finite elements on the unit cube,
// 1-D refinement (1/2, 1, 1/2) tensor prolongations, parity colours. Variants drop functions
// (a spherical shell, as an octree around a surface would; or random), so P loses rows/columns.

#include "../residual_floor.h"
#include "solvers/cholmod_solver.h"
#include "solvers/dense_reference.h"
#include "solvers/multigrid.h"
#include "solvers/multigrid_fallback.h"
#include "solvers/multigrid_pcg.h"
#include "solvers/pcg_solver.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <limits>
#include <memory>
#include <random>
#include <vector>

namespace {

using mcf::HierarchyView;
using mcf::MultigridCycle;
using mcf::MultigridOptions;
using mcf::MultigridSolver;
using mcf::SolveStatus;
using mcf::SparseMatrix;
using Triplets = std::vector<Eigen::Triplet<double, int>>;

struct Problem {
  SparseMatrix A;                                  // finest level
  std::vector<SparseMatrix> P;                     // coarsest first
  std::vector<std::vector<std::uint8_t>> colours;  // per level, coarsest first
  HierarchyView view() const { return {&P, &colours}; }
};

int vid(int N, int i, int j, int k) {
  return i + (N + 1) * (j + (N + 1) * k);
}

double m1(int N, int a, int b) {
  const double h = 1.0 / N;
  if (a != b) return h / 6;
  return (a == 0 || a == N) ? h / 3 : 2 * h / 3;
}
double k1(int N, int a, int b) {
  const double h = 1.0 / N;
  if (a != b) return -1 / h;
  return (a == 0 || a == N) ? 1 / h : 2 / h;
}

SparseMatrix grid_matrix(int N, double dt) {
  const int n = (N + 1) * (N + 1) * (N + 1);
  Triplets t;
  t.reserve(std::size_t(n) * 27);
  for (int k = 0; k <= N; ++k)
    for (int j = 0; j <= N; ++j)
      for (int i = 0; i <= N; ++i)
        for (int dk = -1; dk <= 1; ++dk)
          for (int dj = -1; dj <= 1; ++dj)
            for (int di = -1; di <= 1; ++di) {
              const int a = i + di, b = j + dj, c = k + dk;
              if (a < 0 || b < 0 || c < 0 || a > N || b > N || c > N) continue;
              const double mx = m1(N, i, a), my = m1(N, j, b), mz = m1(N, k, c);
              const double v = mx * my * mz + dt * (k1(N, i, a) * my * mz + mx * k1(N, j, b) * mz +
                                                    mx * my * k1(N, k, c));
              t.emplace_back(vid(N, i, j, k), vid(N, a, b, c), v);
            }
  SparseMatrix A(n, n);
  A.setFromTriplets(t.begin(), t.end());
  A.makeCompressed();
  return A;
}

/// Prolongation from the grid with Nc cells per axis to 2 Nc.
SparseMatrix grid_prolongation(int Nc) {
  const int N = 2 * Nc;
  Triplets t;
  for (int K = 0; K <= Nc; ++K)
    for (int J = 0; J <= Nc; ++J)
      for (int I = 0; I <= Nc; ++I)
        for (int dk = -1; dk <= 1; ++dk)
          for (int dj = -1; dj <= 1; ++dj)
            for (int di = -1; di <= 1; ++di) {
              const int a = 2 * I + di, b = 2 * J + dj, c = 2 * K + dk;
              if (a < 0 || b < 0 || c < 0 || a > N || b > N || c > N) continue;
              const double w = (di ? 0.5 : 1.0) * (dj ? 0.5 : 1.0) * (dk ? 0.5 : 1.0);
              t.emplace_back(vid(N, a, b, c), vid(Nc, I, J, K), w);
            }
  SparseMatrix P((N + 1) * (N + 1) * (N + 1), (Nc + 1) * (Nc + 1) * (Nc + 1));
  P.setFromTriplets(t.begin(), t.end());
  P.makeCompressed();
  return P;
}

std::vector<std::uint8_t> grid_colours(int N) {
  std::vector<std::uint8_t> c(std::size_t((N + 1) * (N + 1) * (N + 1)));
  for (int k = 0; k <= N; ++k)
    for (int j = 0; j <= N; ++j)
      for (int i = 0; i <= N; ++i)
        c[std::size_t(vid(N, i, j, k))] = std::uint8_t((i & 1) | (j & 1) << 1 | (k & 1) << 2);
  return c;
}

enum class Drop { none, shell, random };

/// Levels of depth coarsest..depth. Drop::shell keeps the finest functions near a sphere of
/// radius 0.3 (and the coarse functions with a kept child), Drop::random drops 15 %.
Problem make_problem(int depth, int coarsest, double dt, Drop drop = Drop::none) {
  const int nl = depth - coarsest + 1;
  std::vector<SparseMatrix> Pfull;
  std::vector<std::vector<std::uint8_t>> col;
  for (int d = coarsest; d < depth; ++d) Pfull.push_back(grid_prolongation(1 << d));
  for (int d = coarsest; d <= depth; ++d) col.push_back(grid_colours(1 << d));
  SparseMatrix Afull = grid_matrix(1 << depth, dt);
  // Kept masks, finest first.
  std::vector<std::vector<char>> keep(static_cast<std::size_t>(nl));
  const int N = 1 << depth;
  keep.back().assign(std::size_t(Afull.rows()), 1);
  if (drop != Drop::none) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> U(0, 1);
    for (int k = 0; k <= N; ++k)
      for (int j = 0; j <= N; ++j)
        for (int i = 0; i <= N; ++i) {
          const double x = double(i) / N - 0.5, y = double(j) / N - 0.5, z = double(k) / N - 0.5;
          const double r = std::sqrt(x * x + y * y + z * z);
          const bool kept = drop == Drop::shell ? std::abs(r - 0.3) < 2.5 / N : U(rng) > 0.15;
          keep.back()[std::size_t(vid(N, i, j, k))] = kept;
        }
  }
  for (int l = nl - 2; l >= 0; --l) {
    const SparseMatrix& P = Pfull[std::size_t(l)];
    keep[std::size_t(l)].assign(std::size_t(P.cols()), 0);
    for (int J = 0; J < P.outerSize(); ++J)
      for (SparseMatrix::InnerIterator it(P, J); it; ++it)
        if (keep[std::size_t(l) + 1][std::size_t(it.row())])
          keep[std::size_t(l)][std::size_t(J)] = 1;
  }
  std::vector<std::vector<int>> map(static_cast<std::size_t>(nl));
  std::vector<int> count(static_cast<std::size_t>(nl), 0);
  for (int l = 0; l < nl; ++l) {
    map[std::size_t(l)].assign(keep[std::size_t(l)].size(), -1);
    for (std::size_t i = 0; i < keep[std::size_t(l)].size(); ++i)
      if (keep[std::size_t(l)][i]) map[std::size_t(l)][i] = count[std::size_t(l)]++;
  }
  auto select = [](const SparseMatrix& M, const std::vector<int>& rmap,
                   const std::vector<int>& cmap, int nr, int nc) {
    Triplets t;
    for (int J = 0; J < M.outerSize(); ++J)
      for (SparseMatrix::InnerIterator it(M, J); it; ++it)
        if (rmap[std::size_t(it.row())] >= 0 && cmap[std::size_t(J)] >= 0)
          t.emplace_back(rmap[std::size_t(it.row())], cmap[std::size_t(J)], it.value());
    SparseMatrix S(nr, nc);
    S.setFromTriplets(t.begin(), t.end());
    S.makeCompressed();
    return S;
  };
  Problem pr;
  pr.A = select(Afull, map.back(), map.back(), count.back(), count.back());
  for (int l = 0; l + 1 < nl; ++l)
    pr.P.push_back(select(Pfull[std::size_t(l)], map[std::size_t(l) + 1], map[std::size_t(l)],
                          count[std::size_t(l) + 1], count[std::size_t(l)]));
  for (int l = 0; l < nl; ++l) {
    std::vector<std::uint8_t> c(static_cast<std::size_t>(count[std::size_t(l)]));
    for (std::size_t i = 0; i < map[std::size_t(l)].size(); ++i)
      if (map[std::size_t(l)][i] >= 0)
        c[std::size_t(map[std::size_t(l)][i])] = col[std::size_t(l)][i];
    pr.colours.push_back(std::move(c));
  }
  return pr;
}

Eigen::MatrixXd random_matrix(Eigen::Index n, Eigen::Index k, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> N01;
  Eigen::MatrixXd M(n, k);
  for (Eigen::Index c = 0; c < k; ++c)
    for (Eigen::Index i = 0; i < n; ++i) M(i, c) = N01(rng);
  return M;
}

double rel_diff(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).norm() / b.norm();
}

void expect_galerkin(const MultigridSolver& mg, const Problem& pr) {
  ASSERT_EQ(mg.levels(), int(pr.P.size()) + 1);
  SparseMatrix Af = pr.A;
  for (int l = int(pr.P.size()) - 1; l >= 0; --l) {
    const SparseMatrix& P = pr.P[std::size_t(l)];
    SparseMatrix AP = Af * P;
    SparseMatrix Ac = SparseMatrix(P.transpose()) * AP;
    const SparseMatrix& ours = mg.level_matrix(l);
    ASSERT_EQ(ours.rows(), Ac.rows());
    const double err = SparseMatrix(ours - Ac).norm() / Ac.norm();
    EXPECT_LT(err, 1e-12) << "level " << l;
    Af = ours;  // compare the next level against the product of our own (symmetrized) operator
  }
}

TEST(Multigrid, GalerkinMatchesBruteForceAndUpdatesNumerically) {
  for (Drop drop : {Drop::none, Drop::shell, Drop::random}) {
    SCOPED_TRACE(int(drop));
    Problem pr = make_problem(4, 1, 0.05, drop);
    MultigridSolver mg;
    auto rep = mg.set_matrix(pr.A, pr.view());
    ASSERT_EQ(rep.status, SolveStatus::converged) << rep.message;
    EXPECT_EQ(mg.symbolic_builds(), 1);
    for (int l = 0; l < mg.levels(); ++l) EXPECT_TRUE(mg.level_is_coloured(l)) << l;
    expect_galerkin(mg, pr);

    // New values, same pattern: no new symbolic build, coarse operators follow.
    Problem pr2 = make_problem(4, 1, 0.7, drop);
    for (Eigen::Index e = 0; e < pr2.A.nonZeros(); ++e)
      pr2.A.valuePtr()[e] *= 1.0 + 0.01 * double(e % 7);
    pr2.A = SparseMatrix(0.5 * (pr2.A + SparseMatrix(pr2.A.transpose())));
    ASSERT_EQ(pr2.A.nonZeros(), pr.A.nonZeros());
    rep = mg.set_matrix(pr2.A, pr2.view());
    ASSERT_EQ(rep.status, SolveStatus::converged) << rep.message;
    EXPECT_EQ(mg.symbolic_builds(), 1);
    EXPECT_EQ(mg.numeric_builds(), 2);
    expect_galerkin(mg, pr2);
  }
}

// Zero cycles would return the warm start unchanged as a solve: refused, the iterate untouched.
TEST(Multigrid, ZeroCyclesIsAFailedSolve) {
  Problem pr = make_problem(3, 1, 0.05);
  MultigridOptions o;
  o.cycles = 0;
  MultigridSolver mg(o);
  ASSERT_TRUE(mg.set_matrix(pr.A, pr.view()).ok());
  const Eigen::MatrixXd B = random_matrix(pr.A.rows(), 3, 5);
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(pr.A.rows(), 3);
  const mcf::SolveReport r = mg.solve(B, X);
  EXPECT_EQ(r.status, SolveStatus::failed);
  EXPECT_NE(r.message.find("cycles must be at least 1"), std::string::npos) << r.message;
  EXPECT_EQ(X, Eigen::MatrixXd::Zero(pr.A.rows(), 3));
}

TEST(Multigrid, HierarchyChangeTriggersSymbolicBuild) {
  Problem a = make_problem(3, 1, 0.05);
  Problem b = make_problem(3, 1, 0.05, Drop::random);
  MultigridSolver mg;
  ASSERT_TRUE(mg.set_matrix(a.A, a.view()).ok());
  ASSERT_TRUE(mg.set_matrix(a.A, a.view()).ok());
  EXPECT_EQ(mg.symbolic_builds(), 1);
  ASSERT_TRUE(mg.set_matrix(b.A, b.view()).ok());
  EXPECT_EQ(mg.symbolic_builds(), 2);
  expect_galerkin(mg, b);
}

TEST(Multigrid, PatternKeySkipsTheComparisonOnly) {
  Problem a = make_problem(3, 1, 0.05);
  Problem a2 = make_problem(3, 1, 0.7);  // same pattern, other values
  ASSERT_EQ(a2.A.nonZeros(), a.A.nonZeros());
  Problem b = make_problem(3, 1, 0.05, Drop::random);
  ASSERT_NE(b.A.nonZeros(), a.A.nonZeros());
  const std::uint64_t key = mcf::new_pattern_key(), other = mcf::new_pattern_key();
  EXPECT_NE(key, 0u);
  EXPECT_NE(key, other);

  auto keyed = [](const Problem& p, std::uint64_t k) {
    HierarchyView v = p.view();
    v.pattern_key = k;
    return v;
  };
  MultigridSolver vouched, compared;
  ASSERT_TRUE(vouched.set_matrix(a.A, keyed(a, key)).ok());
  ASSERT_TRUE(compared.set_matrix(a.A, a.view()).ok());
  ASSERT_TRUE(vouched.set_matrix(a2.A, keyed(a2, key)).ok());
  ASSERT_TRUE(compared.set_matrix(a2.A, a2.view()).ok());
  EXPECT_EQ(vouched.pattern_comparisons(), 0);
  EXPECT_EQ(compared.pattern_comparisons(), 1);
  EXPECT_EQ(vouched.symbolic_builds(), 1);
  EXPECT_EQ(vouched.numeric_builds(), 2);
  expect_galerkin(vouched, a2);
  // Same operators, same cycle: bitwise the same iterate.
  const Eigen::MatrixXd B = random_matrix(a.A.rows(), 3, 5);
  Eigen::MatrixXd X1, X2;
  ASSERT_TRUE(vouched.solve(B, X1).ok());
  ASSERT_TRUE(compared.solve(B, X2).ok());
  EXPECT_EQ((X1 - X2).cwiseAbs().maxCoeff(), 0.0);

  // Another key is not vouched for: compared, and still no symbolic build.
  ASSERT_TRUE(vouched.set_matrix(a.A, keyed(a, other)).ok());
  EXPECT_EQ(vouched.pattern_comparisons(), 1);
  EXPECT_EQ(vouched.symbolic_builds(), 1);
  // A key wrongly kept across a change of the number of nonzeros is caught by the O(1) checks.
  ASSERT_TRUE(vouched.set_matrix(b.A, keyed(b, other)).ok());
  EXPECT_EQ(vouched.symbolic_builds(), 2);
  expect_galerkin(vouched, b);
}

// A third term (s S, the stabilization of an increment) is added last, entry by entry: the levels
// and the iterate are bitwise those of set_matrix on sum_on_pattern's matrix, which equals
// Eigen's a M + b K + s S; s = 0 gives bitwise the two-term sum.
TEST(Multigrid, SetMatrixSumWithAThirdTermEqualsSetMatrixOfTheSum) {
  const Problem pm = make_problem(4, 1, 0.0, Drop::shell);
  const Problem pk = make_problem(4, 1, 1.0, Drop::shell);
  const Problem ps = make_problem(4, 1, 0.3, Drop::shell);
  ASSERT_TRUE(mcf::same_pattern(pm.A, ps.A));
  const SparseMatrix &M = pm.A, &K = pk.A, &S = ps.A;
  const Eigen::MatrixXd B = random_matrix(M.rows(), 3, 11);
  MultigridSolver fused, reference, two_terms;
  for (const double s : {0.7, 0.0}) {
    SCOPED_TRACE(s);
    SparseMatrix sum = M;
    mcf::sum_on_pattern(mcf::MatrixSum(1.0, M, 0.05, K, s, S), sum);
    const SparseMatrix eigen = 1.0 * M + 0.05 * K + s * S;
    EXPECT_LE(SparseMatrix(sum - eigen).coeffs().cwiseAbs().maxCoeff(),
              1e-15 * eigen.coeffs().cwiseAbs().maxCoeff());
    ASSERT_TRUE(fused.set_matrix_sum(mcf::MatrixSum(1.0, M, 0.05, K, s, S), pm.view()).ok());
    ASSERT_TRUE(reference.set_matrix(sum, pm.view()).ok());
    for (int l = 0; l < fused.levels(); ++l) {
      const SparseMatrix Lf = fused.level_matrix(l), Lr = reference.level_matrix(l);
      EXPECT_TRUE(std::equal(Lf.valuePtr(), Lf.valuePtr() + Lf.nonZeros(), Lr.valuePtr()))
          << "level " << l;
    }
    Eigen::MatrixXd X1, X2;
    ASSERT_TRUE(fused.solve(B, X1).ok());
    ASSERT_TRUE(reference.solve(B, X2).ok());
    EXPECT_EQ((X1 - X2).cwiseAbs().maxCoeff(), 0.0);
    if (s == 0.0) {
      ASSERT_TRUE(two_terms.set_matrix_sum(1.0, M, 0.05, K, pm.view()).ok());
      Eigen::MatrixXd X3;
      ASSERT_TRUE(two_terms.solve(B, X3).ok());
      EXPECT_EQ((X1 - X3).cwiseAbs().maxCoeff(), 0.0);
    }
  }
}

// set_matrix_sum writes a M + b K straight into the finest level; it must give bitwise the levels
// and the iterate that set_matrix gives for the sum formed by sum_on_pattern: on a new pattern
// (symbolic set-up), on a refresh compared or vouched for by a key, and with b = 0.
TEST(Multigrid, SetMatrixSumEqualsSetMatrixOfTheSum) {
  for (Drop drop : {Drop::none, Drop::shell}) {
    SCOPED_TRACE(int(drop));
    const Problem pm = make_problem(4, 1, 0.0, drop);  // the trilinear mass
    const Problem pk = make_problem(4, 1, 1.0, drop);  // mass + stiffness: another SPD matrix
    ASSERT_TRUE(mcf::same_pattern(pm.A, pk.A));
    const SparseMatrix &M = pm.A, &K = pk.A;
    const Eigen::MatrixXd B = random_matrix(M.rows(), 3, 7);
    const std::uint64_t key = mcf::new_pattern_key();
    MultigridSolver fused, reference;
    struct Call {
      double a, b;
      std::uint64_t key;
    };
    for (const Call c :
         {Call{1.0, 0.05, key}, Call{0.5, 0.2, key}, Call{2.0, 0.0, 0}, Call{1.0, 1e-3, 0}}) {
      SCOPED_TRACE(c.a);
      HierarchyView v = pm.view();
      v.pattern_key = c.key;
      SparseMatrix S = M;
      mcf::sum_on_pattern(c.a, M, c.b, K, S);
      ASSERT_TRUE(fused.set_matrix_sum(c.a, M, c.b, K, v).ok());
      ASSERT_TRUE(reference.set_matrix(S, pm.view()).ok());
      ASSERT_EQ(fused.levels(), reference.levels());
      for (int l = 0; l < fused.levels(); ++l) {
        const SparseMatrix Lf = fused.level_matrix(l), Lr = reference.level_matrix(l);
        ASSERT_TRUE(mcf::same_pattern(Lf, Lr)) << "level " << l;
        EXPECT_TRUE(std::equal(Lf.valuePtr(), Lf.valuePtr() + Lf.nonZeros(), Lr.valuePtr()))
            << "level " << l;
      }
      Eigen::MatrixXd X1, X2;
      ASSERT_TRUE(fused.solve(B, X1).ok());
      ASSERT_TRUE(reference.solve(B, X2).ok());
      EXPECT_EQ((X1 - X2).cwiseAbs().maxCoeff(), 0.0);
      EXPECT_GT(X1.norm(), 0.0);
    }
    EXPECT_EQ(fused.symbolic_builds(), 1);
    EXPECT_EQ(fused.numeric_builds(), 4);
    EXPECT_EQ(fused.pattern_comparisons(), 2);  // the two calls without a key
  }
}

/// A's entries with each column rotated by (j mod its length) places: the same matrix, stored
/// with the diagonal first, last or in between.
SparseMatrix rotate_columns(const SparseMatrix& A) {
  SparseMatrix R = A;
  for (int j = 0; j < R.cols(); ++j) {
    const int p0 = R.outerIndexPtr()[j], n = R.outerIndexPtr()[j + 1] - p0;
    if (n == 0) continue;
    std::rotate(R.innerIndexPtr() + p0, R.innerIndexPtr() + p0 + j % n, R.innerIndexPtr() + p0 + n);
    std::rotate(R.valuePtr() + p0, R.valuePtr() + p0 + j % n, R.valuePtr() + p0 + n);
  }
  return R;
}

bool same_values(const SparseMatrix& X, const SparseMatrix& Y) {
  return mcf::same_pattern(X, Y) &&
         std::equal(X.valuePtr(), X.valuePtr() + X.nonZeros(), Y.valuePtr());
}

/// Largest relative difference, over the coarse levels, of two solvers' operators (Frobenius).
double coarse_difference(const MultigridSolver& x, const MultigridSolver& y) {
  double worst = 0;
  for (int l = 0; l + 1 < x.levels(); ++l) {
    const SparseMatrix X = x.level_matrix(l), Y = y.level_matrix(l);
    EXPECT_TRUE(mcf::same_pattern(X, Y)) << "level " << l;
    worst = std::max(worst, SparseMatrix(X - Y).norm() / Y.norm());
  }
  return worst;
}

// galerkin_by_term keeps Pᵀ M P, Pᵀ K P (and Pᵀ S P) per level and recomputes only the terms
// whose values changed: the coarse operators equal those of the sum's Galerkin product to 1e-12
// (linearity; rounding differs), the finest level bitwise, and a cMCF-like sequence (M changes,
// K does not) computes one product per level instead of two.
TEST(Multigrid, GalerkinByTermRefreshesOnlyChangedTermsAndMatchesTheSum) {
  const Problem pm = make_problem(4, 1, 0.0, Drop::shell);
  const Problem pk = make_problem(4, 1, 1.0, Drop::shell);
  const Problem ps = make_problem(4, 1, 0.3, Drop::shell);
  const SparseMatrix &M = pm.A, &K = pk.A, &S = ps.A;
  SparseMatrix M2 = M;  // "the mass at the next step": other values on the same pattern
  for (Eigen::Index p = 0; p < M2.nonZeros(); ++p)
    M2.valuePtr()[p] *= 1.0 + 0.1 * std::sin(double(p));
  M2 = SparseMatrix(0.5 * (M2 + SparseMatrix(M2.transpose())));
  ASSERT_TRUE(mcf::same_pattern(M, M2));
  SparseMatrix K2 = K;
  K2.coeffs() *= 1.25;
  const Eigen::MatrixXd B = random_matrix(M.rows(), 3, 5);
  MultigridOptions by_term_options;
  by_term_options.galerkin_by_term = true;
  by_term_options.cycles = 3;
  MultigridOptions plain_options = by_term_options;
  plain_options.galerkin_by_term = false;
  MultigridSolver by_term(by_term_options), plain(plain_options);
  struct Call {
    double a;
    const SparseMatrix* M;
    double b;
    const SparseMatrix* K;
    double s;               // 0: two terms
    std::int64_t products;  // term products this call must compute
  };
  const int coarse = int(pm.P.size());
  const std::int64_t none = 0, one = coarse, two = 2 * coarse, three = 3 * coarse;
  for (const Call c : {Call{1.0, &M, 0.05, &K, 0, two},      // new pattern: both terms
                       Call{1.0, &M2, 0.05, &K, 0, one},     // cMCF: the mass changed
                       Call{1.0, &M2, 0.2, &K, 0, none},     // new coefficients, same terms
                       Call{1.0, &M2, 0.2, &K2, 0, one},     // the stiffness changed
                       Call{1.0, &M, 0.2, &K2, 0.7, three},  // a third term: all anew
                       Call{1.0, &M2, 0.2, &K2, 0.7, one}}) {
    SCOPED_TRACE(c.products);
    const std::int64_t before = by_term.term_products();
    const mcf::MatrixSum sum = c.s > 0 ? mcf::MatrixSum(c.a, *c.M, c.b, *c.K, c.s, S)
                                       : mcf::MatrixSum(c.a, *c.M, c.b, *c.K);
    ASSERT_TRUE(by_term.set_matrix_sum(sum, pm.view()).ok());
    ASSERT_TRUE(plain.set_matrix_sum(sum, pm.view()).ok());
    EXPECT_EQ(by_term.term_products() - before, c.products);
    const SparseMatrix Fb = by_term.level_matrix(coarse), Fp = plain.level_matrix(coarse);
    EXPECT_TRUE(same_values(Fb, Fp));  // the finest level is the sum itself
    EXPECT_LE(coarse_difference(by_term, plain), 1e-12);
    Eigen::MatrixXd X1, X2;
    ASSERT_TRUE(by_term.solve(B, X1).ok());
    ASSERT_TRUE(plain.solve(B, X2).ok());
    EXPECT_LE((X1 - X2).norm(), 1e-10 * X2.norm());
  }
  EXPECT_EQ(plain.term_products(), 0);
  // A plain set_matrix drops the kept terms; the next sum recomputes them all.
  ASSERT_TRUE(by_term.set_matrix(M, pm.view()).ok());
  const std::int64_t before = by_term.term_products();
  ASSERT_TRUE(by_term.set_matrix_sum(1.0, M, 0.05, K, pm.view()).ok());
  EXPECT_EQ(by_term.term_products() - before, two);
}

// galerkin_refresh = 3: of a sequence of sums on one pattern, only calls 1, 4, 7 recompute the
// coarse operators; the others keep them (the coarse level of call 2 equals call 1's bitwise)
// while the finest level takes the new values, so solving to a tolerance gives the direct
// solution of each call's own matrix. A new pattern refreshes at once.
TEST(Multigrid, LaggedGalerkinRefreshKeepsCoarseOperatorsAndConvergesToTheNewMatrix) {
  const Problem pm = make_problem(4, 1, 0.0, Drop::shell);
  const Problem pk = make_problem(4, 1, 1.0, Drop::shell);
  const SparseMatrix &M = pm.A, &K = pk.A;
  const Eigen::MatrixXd B = random_matrix(M.rows(), 3, 7);
  MultigridOptions o;
  o.cycles = 100;
  o.tolerance = 1e-10;
  o.galerkin_refresh = 3;
  MultigridSolver mg(o);
  const int coarse = int(pm.P.size());
  SparseMatrix first_coarse;
  for (int call = 0; call < 7; ++call) {
    SCOPED_TRACE(call);
    SparseMatrix Mc = M;  // the mass of step `call`: other values on the same pattern
    for (Eigen::Index p = 0; p < Mc.nonZeros(); ++p)
      Mc.valuePtr()[p] *= 1.0 + 0.2 * std::sin(double(p + call));
    Mc = SparseMatrix(0.5 * (Mc + SparseMatrix(Mc.transpose())));
    const mcf::MatrixSum sum(1.0, Mc, 0.05, K);
    ASSERT_TRUE(mg.set_matrix_sum(sum, pm.view()).ok());
    EXPECT_EQ(mg.numeric_builds(), 1 + call / 3);
    EXPECT_EQ(mg.lagged_refreshes(), call - call / 3);
    const SparseMatrix A = SparseMatrix(Mc + 0.05 * K);
    EXPECT_LE(SparseMatrix(mg.level_matrix(coarse) - A).norm(), 1e-14 * A.norm());
    if (call == 0) first_coarse = mg.level_matrix(coarse - 1);
    if (call == 1) {
      EXPECT_TRUE(same_values(mg.level_matrix(coarse - 1), first_coarse));
    }
    Eigen::MatrixXd X;
    const mcf::SolveReport r = mg.solve(B, X);
    ASSERT_TRUE(r.ok()) << r.message;
    Eigen::SimplicialLDLT<SparseMatrix> direct(A);
    EXPECT_LE((X - direct.solve(B)).norm(), 1e-8 * X.norm());
  }
  // The same matrix set again: a lagged call's coarse operators are the refreshed ones, so two
  // cycles give bitwise the result of a solver that refreshes every call.
  {
    MultigridOptions two = o;
    two.cycles = 2;
    two.tolerance = 0;
    MultigridOptions every = two;
    every.galerkin_refresh = 1;
    MultigridSolver lagging(two), refreshing(every);
    const mcf::MatrixSum sum(1.0, M, 0.05, K);
    for (int call = 0; call < 3; ++call) {
      ASSERT_TRUE(lagging.set_matrix_sum(sum, pm.view()).ok());
      ASSERT_TRUE(refreshing.set_matrix_sum(sum, pm.view()).ok());
      Eigen::MatrixXd X1, X2;
      ASSERT_TRUE(lagging.solve(B, X1).ok());
      ASSERT_TRUE(refreshing.solve(B, X2).ok());
      EXPECT_EQ((X1 - X2).norm(), 0.0) << call;
    }
    EXPECT_EQ(lagging.lagged_refreshes(), 2);
  }
  // Another pattern: the coarse operators are set up anew whatever the count.
  const std::int64_t builds = mg.numeric_builds();
  const Problem other = make_problem(5, 2, 1e-2, Drop::shell);
  ASSERT_TRUE(mg.set_matrix(other.A, other.view()).ok());
  ASSERT_TRUE(mg.set_matrix(M, pm.view()).ok());
  EXPECT_EQ(mg.numeric_builds(), builds + 2);
}

// mixed_precision: single-precision finest sweeps inside a double-precision residual correction
// converge to the solution of A x = b (a relative residual of 1e-11 and the direct solution), where
// rounded finest sweeps without the correction would stall near 1e-8.
TEST(Multigrid, MixedPrecisionConvergesToTheDirectSolution) {
  const Problem pr = make_problem(5, 2, 1e-2, Drop::shell);
  const Eigen::MatrixXd B = random_matrix(pr.A.rows(), 3, 3);
  Eigen::SimplicialLDLT<SparseMatrix> direct(pr.A);
  const Eigen::MatrixXd exact = direct.solve(B);
  for (const MultigridCycle c : {MultigridCycle::V, MultigridCycle::W}) {
    MultigridOptions o;
    o.cycle = c;
    o.cycles = 200;
    o.tolerance = 1e-11;
    o.mixed_precision = true;
    MultigridSolver mg(o);
    ASSERT_TRUE(mg.set_matrix(pr.A, pr.view()).ok());
    EXPECT_EQ(mg.level_sweep_entry_bytes(mg.levels() - 1), 6);
    Eigen::MatrixXd X;
    const mcf::SolveReport r = mg.solve(B, X);
    EXPECT_EQ(r.status, SolveStatus::converged);
    EXPECT_LT(r.relative_residual, 1e-11);
    EXPECT_LT(rel_diff(X, exact), 1e-9);
    // Switching back to double precision sets the finest sweeps up anew.
    o.mixed_precision = false;
    mg.set_options(o);
    ASSERT_TRUE(mg.set_matrix(pr.A, pr.view()).ok());
    EXPECT_EQ(mg.level_sweep_entry_bytes(mg.levels() - 1), 10);
    EXPECT_EQ(mg.symbolic_builds(), 2);
  }
}

/// The finest level stores each column's diagonal last and remembers where the caller had it
/// (solvers/smoother.h, diagonal_last): a value refresh and set_matrix_sum must put every entry
/// back in its place, and the pattern comparison must recognise the caller's order. Checked with
/// the caller's diagonal at every rank (columns rotated), against the same matrix stored sorted.
TEST(Multigrid, FinestDiagonalStoredLastWhereverTheCallerHasIt) {
  const Problem pm = make_problem(5, 2, 0.0, Drop::shell);
  const Problem pk = make_problem(5, 2, 1.0, Drop::shell);
  const SparseMatrix M = rotate_columns(pm.A), K = rotate_columns(pk.A);
  int ranks_seen = 0;  // teeth: the rotation really moves the diagonal around
  for (int j = 0; j < M.cols(); ++j) {
    const int p0 = M.outerIndexPtr()[j];
    if (M.innerIndexPtr()[p0] != j && M.innerIndexPtr()[M.outerIndexPtr()[j + 1] - 1] != j)
      ++ranks_seen;
  }
  ASSERT_GT(ranks_seen, M.cols() / 2);
  const Eigen::MatrixXd B = random_matrix(M.rows(), 3, 31);
  MultigridSolver rotated, sorted;
  ASSERT_TRUE(rotated.set_matrix(M, pm.view()).ok());
  ASSERT_TRUE(sorted.set_matrix(pm.A, pm.view()).ok());
  ASSERT_TRUE(rotated.level_has_compact_smoother(rotated.levels() - 1));
  for (int l = 0; l < rotated.levels(); ++l)
    EXPECT_TRUE(same_values(rotated.level_matrix(l), sorted.level_matrix(l))) << "level " << l;
  Eigen::MatrixXd X1, X2;
  ASSERT_TRUE(rotated.solve(B, X1).ok());
  ASSERT_TRUE(sorted.solve(B, X2).ok());
  EXPECT_LE((X1 - X2).cwiseAbs().maxCoeff(), 1e-12 * X2.cwiseAbs().maxCoeff());  // term order only
  EXPECT_GT(X2.norm(), 0.0);

  // New values, compared pattern: no new symbolic build, every value in its place.
  const SparseMatrix M2 = M * 2.0;
  ASSERT_TRUE(rotated.set_matrix(M2, pm.view()).ok());
  EXPECT_EQ(rotated.symbolic_builds(), 1);
  EXPECT_EQ(rotated.pattern_comparisons(), 1);
  SparseMatrix twice = pm.A * 2.0;
  EXPECT_TRUE(same_values(rotated.level_matrix(rotated.levels() - 1), twice));

  // The sum written entry by entry: the level equals the sorted sum.
  SparseMatrix S = pm.A;
  mcf::sum_on_pattern(1.0, pm.A, 0.05, pk.A, S);
  ASSERT_TRUE(rotated.set_matrix_sum(1.0, M, 0.05, K, pm.view()).ok());
  EXPECT_EQ(rotated.symbolic_builds(), 1);
  ASSERT_TRUE(sorted.set_matrix(S, pm.view()).ok());
  for (int l = 0; l < rotated.levels(); ++l)
    EXPECT_TRUE(same_values(rotated.level_matrix(l), sorted.level_matrix(l))) << "sum, level " << l;

  // The same matrix in the sorted order is another stored pattern: a new symbolic build.
  ASSERT_TRUE(rotated.set_matrix(pm.A, pm.view()).ok());
  EXPECT_EQ(rotated.symbolic_builds(), 2);
  EXPECT_TRUE(same_values(rotated.level_matrix(rotated.levels() - 1), pm.A));
}

// The kept finest matrix follows every set_matrix: the values of the same pattern, a sum, and a
// new pattern (the caller's diagonal first in its columns, the solver's last: a real permutation).
TEST(Multigrid, FinestMatrixIsTheFinestLevelAfterEverySetMatrix) {
  const Problem pm = make_problem(5, 2, 0.0, Drop::shell);
  const Problem pk = make_problem(5, 2, 1.0, Drop::shell);
  const SparseMatrix M = rotate_columns(pm.A), K = rotate_columns(pk.A);
  MultigridSolver mg;
  const auto expect_finest = [&](const SparseMatrix& A) {
    const SparseMatrix& kept = mg.finest_matrix();
    EXPECT_TRUE(same_values(kept, mg.level_matrix(mg.levels() - 1)));
    EXPECT_LE(SparseMatrix(kept - A).norm(), 1e-15 * A.norm());
  };
  // (Compared with the sorted matrices: Eigen's arithmetic needs sorted columns.)
  ASSERT_TRUE(mg.set_matrix(M, pm.view()).ok());
  expect_finest(pm.A);
  const double* storage = mg.finest_matrix().valuePtr();
  ASSERT_TRUE(mg.set_matrix(SparseMatrix(M * 3.0), pm.view()).ok());
  expect_finest(SparseMatrix(pm.A * 3.0));
  EXPECT_EQ(mg.finest_matrix().valuePtr(), storage);  // same pattern: refreshed in place
  ASSERT_TRUE(mg.set_matrix_sum(1.0, M, 0.05, K, pm.view()).ok());
  expect_finest(SparseMatrix(pm.A + 0.05 * pk.A));
  ASSERT_TRUE(mg.set_matrix(pk.A, pk.view()).ok());  // another stored pattern
  EXPECT_EQ(mg.symbolic_builds(), 2);
  expect_finest(pk.A);
}

// PCG preconditioned by the cycle hands M and K to both halves: bitwise as set_matrix on the sum.
TEST(Multigrid, PcgSetMatrixSumEqualsSetMatrixOfTheSum) {
  const Problem pm = make_problem(4, 1, 0.0, Drop::shell),
                pk = make_problem(4, 1, 1.0, Drop::shell);
  ASSERT_TRUE(mcf::same_pattern(pm.A, pk.A));
  mcf::PcgOptions pcg;
  pcg.max_iterations = 3;
  pcg.relative_tolerance = 1e-14;
  MultigridOptions cycle;
  mcf::MultigridPcgSolver fused(cycle, pcg), reference(cycle, pcg);
  for (const double b : {0.05, 0.2}) {
    SparseMatrix S = pm.A;
    mcf::sum_on_pattern(1.0, pm.A, b, pk.A, S);
    ASSERT_TRUE(fused.set_matrix_sum(1.0, pm.A, b, pk.A, pm.view()).ok());
    ASSERT_TRUE(reference.set_matrix(S, pm.view()).ok());
    const Eigen::MatrixXd B = random_matrix(S.rows(), 3, 9);
    Eigen::MatrixXd X1, X2;
    ASSERT_TRUE(fused.solve(B, X1).ok());
    ASSERT_TRUE(reference.solve(B, X2).ok());
    EXPECT_EQ((X1 - X2).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_GT(X1.norm(), 0.0);
  }
}

// Operands off one pattern (here K has fewer entries: a diagonal) are not refused: the solver gets
// Eigen's general sum, exactly as set_matrix on that sum.
TEST(Multigrid, SetMatrixSumOffOnePatternSetsTheGeneralSum) {
  const Problem a = make_problem(3, 1, 0.05);
  const SparseMatrix D = SparseMatrix(a.A.diagonal().asDiagonal());
  ASSERT_FALSE(mcf::summable(a.A, D));
  MultigridSolver fused, reference;
  ASSERT_TRUE(fused.set_matrix(a.A, a.view()).ok());  // then the other matrix, on the same solver
  ASSERT_TRUE(fused.set_matrix_sum(1.0, a.A, 0.3, D, a.view()).ok());
  SparseMatrix S = a.A + 0.3 * D;
  S.makeCompressed();
  ASSERT_TRUE(reference.set_matrix(S, a.view()).ok());
  const Eigen::MatrixXd B = random_matrix(a.A.rows(), 3, 1);
  Eigen::MatrixXd X1, X2;
  ASSERT_TRUE(fused.solve(B, X1).ok());
  ASSERT_TRUE(reference.solve(B, X2).ok());
  EXPECT_LT(rel_diff(X1, X2), 1e-14);
  EXPECT_GT(X1.norm(), 0.0);
  // Not the old matrix's iterate.
  MultigridSolver old;
  ASSERT_TRUE(old.set_matrix(a.A, a.view()).ok());
  Eigen::MatrixXd X0;
  ASSERT_TRUE(old.solve(B, X0).ok());
  EXPECT_GT(rel_diff(X1, X0), 1e-3);
}

void expect_converges_to_direct(MultigridCycle cycle, Drop drop) {
  // The full grid at depth 5 makes the reference factorization slow: depth 4 there.
  Problem pr = make_problem(drop == Drop::none ? 4 : 5, 1, 0.05, drop);
  Eigen::SimplicialLDLT<SparseMatrix> ldlt(pr.A);
  ASSERT_EQ(ldlt.info(), Eigen::Success);
  const Eigen::MatrixXd B = random_matrix(pr.A.rows(), 3, 11);
  const Eigen::MatrixXd Xd = ldlt.solve(B);

  MultigridOptions opt;
  opt.cycle = cycle;
  opt.cycles = 40;
  opt.tolerance = 1e-13;
  MultigridSolver mg(opt);
  ASSERT_TRUE(mg.set_matrix(pr.A, pr.view()).ok());
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(pr.A.rows(), 3);
  const auto rep = mg.solve(B, X);
  EXPECT_EQ(rep.status, SolveStatus::converged);
  EXPECT_LT(rel_diff(X, Xd), 1e-8);
  EXPECT_EQ(int(rep.residuals.size()), rep.iterations);
  EXPECT_TRUE(mcf::testing::falls_above_rounding_floor(rep.residuals));
}

TEST(Multigrid, VCycleConvergesToDirectSolution) {
  expect_converges_to_direct(MultigridCycle::V, Drop::none);
}
TEST(Multigrid, WCycleConvergesToDirectSolution) {
  expect_converges_to_direct(MultigridCycle::W, Drop::none);
}
TEST(Multigrid, VCycleConvergesOnShell) {
  expect_converges_to_direct(MultigridCycle::V, Drop::shell);
}
TEST(Multigrid, WCycleConvergesOnShell) {
  expect_converges_to_direct(MultigridCycle::W, Drop::shell);
}

// A semi-definite coarsest level (the octree functions on a face parallel to a grid plane are
// dependent, and a coarse function whose finer functions are all held has a zero row): the
// LDLᵀ factor has a pivot of rounding size, so the coarsest solve uses a generalized inverse,
// which solves every consistent right-hand side. One level makes the coarsest level the only one.
// Here function j := r times function i for pairs of x-neighbours (Wᵀ A W), and one function is
// dropped (zero row and column); an indefinite matrix is still refused.
TEST(Multigrid, SemiDefiniteCoarsestLevelIsSolvedByItsPseudoInverse) {
  const Problem pr = make_problem(3, 3, 0.05);
  const int n = int(pr.A.rows()), N = 8;
  Triplets w;
  std::vector<char> merged(std::size_t(n), 0);
  int pairs = 0;
  for (int k = 0; k <= N; k += 3)
    for (int j = 0; j <= N; j += 2)
      for (int i = 0; i + 1 <= N; i += 4) {
        merged[std::size_t(vid(N, i + 1, j, k))] = 1;
        w.emplace_back(vid(N, i, j, k), vid(N, i + 1, j, k), 0.75);  // column i+1 = 0.75 e_i
        ++pairs;
      }
  const int dropped = vid(N, 5, 5, 5);
  for (int c = 0; c < n; ++c)
    if (!merged[std::size_t(c)] && c != dropped) w.emplace_back(c, c, 1.0);
  SparseMatrix W(n, n);
  W.setFromTriplets(w.begin(), w.end());
  SparseMatrix A = SparseMatrix(W.transpose()) * pr.A * W;
  A.prune(0.0);
  A.makeCompressed();
  ASSERT_EQ(A.coeff(dropped, dropped), 0.0);
  const Eigen::MatrixXd B = W.transpose() * random_matrix(n, 3, 5);  // consistent: in A's range
  Eigen::SimplicialLDLT<SparseMatrix> ldlt(A);
  ASSERT_TRUE(ldlt.info() != Eigen::Success ||
              ldlt.vectorD().cwiseAbs().minCoeff() < 1e-12 * ldlt.vectorD().maxCoeff())
      << "the test matrix must be singular";

  MultigridSolver mg;
  const std::vector<SparseMatrix> none;
  const mcf::SolveReport set = mg.set_matrix(A, HierarchyView{&none, nullptr});
  ASSERT_TRUE(set.ok()) << set.message;
  EXPECT_NE(set.message.find("null space of dimension " + std::to_string(pairs + 1)),
            std::string::npos)
      << set.message;
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(n, 3);
  ASSERT_TRUE(mg.solve(B, X).ok());
  EXPECT_LT(((A * X - B).colwise().norm().array() / B.colwise().norm().array()).maxCoeff(), 1e-11);
  EXPECT_EQ(X.row(dropped).norm(), 0.0);  // no component along a zero row's null direction

  // Multigrid-preconditioned CG passes the preconditioner's note on (it returned PCG's report).
  mcf::MultigridPcgSolver mg_pcg{MultigridOptions{}, mcf::PcgOptions{}};
  const mcf::SolveReport pcg_set = mg_pcg.set_matrix(A, HierarchyView{&none, nullptr});
  ASSERT_TRUE(pcg_set.ok()) << pcg_set.message;
  EXPECT_EQ(pcg_set.message, set.message);

  // Indefinite: one negative eigenvalue, no generalized inverse makes it a flow's system.
  // Positive diagonal, a 2 x 2 principal minor < 0.
  SparseMatrix indefinite = A;
  const int a = vid(N, 2, 0, 0), b = vid(N, 3, 0, 0);
  indefinite.coeffRef(a, b) = indefinite.coeffRef(b, a) =
      3 * std::sqrt(A.coeff(a, a) * A.coeff(b, b));
  const mcf::SolveReport refused = mg.set_matrix(indefinite, HierarchyView{&none, nullptr});
  EXPECT_EQ(refused.status, SolveStatus::not_positive_definite);
  EXPECT_NE(refused.message.find("eigenvalue"), std::string::npos) << refused.message;
}

TEST(Multigrid, RefusesANegativeOrNonFiniteDiagonalInAnyRow) {
  // 16^3 rows: the diagonal's check runs in parallel chunks; a bad entry in any chunk refuses.
  const int N = 15;
  const SparseMatrix A = grid_matrix(N, 1e-3);
  ASSERT_GE(A.rows(), 4096);
  const std::vector<SparseMatrix> none;
  for (const int row : {0, int(A.rows()) / 2 + 7, int(A.rows()) - 1}) {
    for (const double bad : {-1.0, std::numeric_limits<double>::quiet_NaN(),
                             std::numeric_limits<double>::infinity()}) {
      SparseMatrix B = A;
      B.coeffRef(row, row) = bad;
      MultigridSolver mg;
      const mcf::SolveReport rep = mg.set_matrix(B, HierarchyView{&none, nullptr});
      EXPECT_EQ(rep.status, SolveStatus::not_positive_definite) << "row " << row << ", " << bad;
      EXPECT_NE(rep.message.find("diagonal"), std::string::npos) << rep.message;
      // The same solver accepts the sound matrix afterwards.
      EXPECT_TRUE(mg.set_matrix(A, HierarchyView{&none, nullptr}).ok());
    }
  }
}

TEST(Multigrid, OneWCycleReducesResidualTenfold) {
  for (Drop drop : {Drop::none, Drop::shell}) {
    for (double dt : {1e-3, 0.05, 1.0}) {
      Problem pr = make_problem(5, 1, dt, drop);
      MultigridSolver mg;  // defaults: 1 W-cycle, 5 + 5 sweeps
      ASSERT_TRUE(mg.set_matrix(pr.A, pr.view()).ok());
      const Eigen::MatrixXd B = random_matrix(pr.A.rows(), 3, 3);
      Eigen::MatrixXd X = Eigen::MatrixXd::Zero(pr.A.rows(), 3);
      const auto rep = mg.solve(B, X);
      ASSERT_EQ(rep.iterations, 1);
      // Fixed work, checked against nothing: never called converged.
      EXPECT_EQ(rep.status, SolveStatus::max_iterations);
      EXPECT_LT(rep.relative_residual, 0.1) << "dt " << dt << " drop " << int(drop);
      // The reported residual is the true one.
      const double r =
          ((B - pr.A * X).colwise().norm().array() / B.colwise().norm().array()).maxCoeff();
      EXPECT_NEAR(rep.relative_residual, r, 1e-12);
    }
  }
}

TEST(Multigrid, WarmStartAndToleranceStopEarly) {
  Problem pr = make_problem(4, 1, 0.05, Drop::shell);
  MultigridOptions opt;
  opt.cycles = 50;
  opt.tolerance = 1e-6;
  MultigridSolver mg(opt);
  ASSERT_TRUE(mg.set_matrix(pr.A, pr.view()).ok());
  const Eigen::MatrixXd B = random_matrix(pr.A.rows(), 3, 5);
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(pr.A.rows(), 3);
  auto rep = mg.solve(B, X);
  EXPECT_EQ(rep.status, SolveStatus::converged);
  EXPECT_LT(rep.iterations, 50);
  EXPECT_LT(rep.relative_residual, 1e-6);
  // Solving again from the solution: nothing to do.
  rep = mg.solve(B, X);
  EXPECT_EQ(rep.status, SolveStatus::converged);
  EXPECT_EQ(rep.iterations, 0);
  // An unreachable tolerance: the cap is reported.
  opt.cycles = 2;
  opt.tolerance = 1e-30;
  mg.set_options(opt);
  X.setZero();
  rep = mg.solve(B, X);
  EXPECT_EQ(rep.status, SolveStatus::max_iterations);
  EXPECT_EQ(rep.iterations, 2);
}

TEST(Multigrid, WCycleNeedsNoMoreCyclesThanV) {
  for (Drop drop : {Drop::none, Drop::shell}) {
    Problem pr = make_problem(5, 1, 0.05, drop);
    const Eigen::MatrixXd B = random_matrix(pr.A.rows(), 3, 9);
    int its[2];
    for (MultigridCycle c : {MultigridCycle::V, MultigridCycle::W}) {
      MultigridOptions opt;
      opt.cycle = c;
      opt.cycles = 100;
      opt.tolerance = 1e-10;
      MultigridSolver mg(opt);
      ASSERT_TRUE(mg.set_matrix(pr.A, pr.view()).ok());
      Eigen::MatrixXd X = Eigen::MatrixXd::Zero(pr.A.rows(), 3);
      const auto rep = mg.solve(B, X);
      ASSERT_EQ(rep.status, SolveStatus::converged);
      its[c == MultigridCycle::W] = rep.iterations;
    }
    EXPECT_LE(its[1], its[0]) << "V " << its[0] << " W " << its[1];
    std::cout << "[ cycles   ] to 1e-10, drop " << int(drop) << ": V " << its[0] << ", W " << its[1]
              << "\n";
  }
}

TEST(Multigrid, BitwiseIdenticalForOneAndTwoThreads) {
  Problem pr = make_problem(5, 1, 0.05, Drop::none);  // 35937 functions: parallel paths taken
  const Eigen::MatrixXd B = random_matrix(pr.A.rows(), 3, 1);
  Eigen::MatrixXd X[2];
  std::vector<double> res[2];
  SparseMatrix coarse[2];
  for (int t = 0; t < 2; ++t) {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, std::size_t(t + 1));
    MultigridOptions opt;
    opt.cycles = 3;
    MultigridSolver mg(opt);
    ASSERT_TRUE(mg.set_matrix(pr.A, pr.view()).ok());
    X[t] = Eigen::MatrixXd::Zero(pr.A.rows(), 3);
    res[t] = mg.solve(B, X[t]).residuals;
    coarse[t] = mg.level_matrix(mg.levels() - 2);
  }
  EXPECT_EQ((X[0] - X[1]).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(res[0], res[1]);
  ASSERT_EQ(coarse[0].nonZeros(), coarse[1].nonZeros());
  EXPECT_TRUE(std::equal(coarse[0].valuePtr(), coarse[0].valuePtr() + coarse[0].nonZeros(),
                         coarse[1].valuePtr()));
}

/// Serial Gauss-Seidel over `order`: row i's off-diagonal terms in index order, its diagonal
/// exact; with `single`, the off-diagonal values rounded to single precision as the solver's
/// compact smoother rows hold them.
void reference_gs(const SparseMatrix& A, const Eigen::MatrixXd& B, Eigen::MatrixXd& X,
                  const std::vector<int>& order, bool single = false) {
  for (int i : order) {
    double d = 0;
    Eigen::RowVectorXd acc = B.row(i);
    for (SparseMatrix::InnerIterator it(A, i); it; ++it) {
      if (it.row() == i) {
        d = it.value();
        continue;
      }
      const double v = single ? double(float(it.value())) : it.value();
      acc -= v * X.row(it.row());
    }
    X.row(i) = acc * (1.0 / d);
  }
}

/// Every level's sweep is the serial Gauss-Seidel sweep in the order relaxation_order() reports
/// (relaxation blocks, even ones first, colour by colour inside; reverse: the exact reverse), on
/// 2 threads. Only the order of a row's terms differs, so the two agree to rounding; the colour-
/// then-index order over the whole level (the sweep before relaxation blocks) differs visibly on
/// the finest level, which has several blocks, so the comparison can tell orderings apart.
TEST(Multigrid, SweepEqualsSerialGaussSeidelInItsRelaxationOrder) {
  Problem pr = make_problem(5, 2, 0.05, Drop::shell);
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 2);
  MultigridSolver mg;
  ASSERT_TRUE(mg.set_matrix(pr.A, pr.view()).ok());
  for (int l = 0; l < mg.levels(); ++l) {
    const SparseMatrix A = mg.level_matrix(l);
    ASSERT_TRUE(mg.level_is_coloured(l));
    EXPECT_TRUE(mg.level_has_compact_smoother(l)) << "level " << l << " n " << A.rows();
    const bool single = l + 1 < mg.levels();  // the finest level's sweeps keep double values
    const std::vector<int> fwd = mg.relaxation_order(l, false), rev = mg.relaxation_order(l, true);
    ASSERT_EQ(fwd.size(), std::size_t(A.rows()));
    std::vector<int> sorted = fwd;
    std::sort(sorted.begin(), sorted.end());
    for (int i = 0; i < A.rows(); ++i)
      ASSERT_EQ(sorted[std::size_t(i)], i) << "not a permutation, level " << l;
    // The reverse sweep equals the serial sweep in the exact reverse of the forward order (what
    // makes the cycle symmetric); relaxation_order(l, true) may list the independent functions of
    // one colour in another order, which gives the same result.
    const std::vector<int> backward(fwd.rbegin(), fwd.rend());
    const Eigen::MatrixXd B = random_matrix(A.rows(), 3, 21);
    for (bool reverse : {false, true}) {
      Eigen::MatrixXd X = random_matrix(A.rows(), 3, 22), Xr = X, Xo = X;
      mg.gauss_seidel(l, B, X, 2, reverse);
      for (int sweep = 0; sweep < 2; ++sweep) {
        reference_gs(A, B, Xr, reverse ? backward : fwd, single);
        reference_gs(A, B, Xo, reverse ? rev : fwd, single);
      }
      const double scale = Xr.cwiseAbs().maxCoeff();
      EXPECT_LE((X - Xr).cwiseAbs().maxCoeff(), 1e-13 * scale)
          << "level " << l << " reverse " << reverse;
      EXPECT_LE((X - Xo).cwiseAbs().maxCoeff(), 1e-13 * scale)
          << "level " << l << " reverse " << reverse;
    }
  }
  // Teeth: on a finest level of several relaxation blocks (a depth-6 shell: ~27 tiles) the sweep
  // agrees with its own order and not with the global colour-then-index order.
  Problem big = make_problem(6, 4, 0.05, Drop::shell);
  MultigridSolver mg6;
  ASSERT_TRUE(mg6.set_matrix(big.A, big.view()).ok());
  const int top = mg6.levels() - 1;
  const auto& col = big.colours.back();
  std::vector<int> global;
  for (int c = 0; c < 8; ++c)
    for (int i = 0; i < big.A.rows(); ++i)
      if (col[std::size_t(i)] == c) global.push_back(i);
  const std::vector<int> own = mg6.relaxation_order(top, false);
  ASSERT_NE(global, own);
  const Eigen::MatrixXd B = random_matrix(big.A.rows(), 3, 21);
  Eigen::MatrixXd X = random_matrix(big.A.rows(), 3, 22), Xown = X, Xglobal = X;
  mg6.gauss_seidel(top, B, X, 1, false);
  reference_gs(big.A, B, Xown, own);
  reference_gs(big.A, B, Xglobal, global);
  const double scale = Xown.cwiseAbs().maxCoeff();
  EXPECT_LE((X - Xown).cwiseAbs().maxCoeff(), 1e-13 * scale);
  EXPECT_GT((X - Xglobal).cwiseAbs().maxCoeff(), 1e-6 * scale);
}

/// The parallel sweep relaxes blocks of one parity at the same time, so it is a serial
/// Gauss-Seidel sweep only if no function couples with one two or more blocks away. Checked on
/// every level's matrix, with levels of several blocks (a depth-7 shell, whose finest level couples
/// functions more than a tile apart) so that the check is not vacuous: with one-tile blocks it
/// fails.
TEST(Multigrid, RelaxationBlocksOfOneParityNeverCouple) {
  Problem pr = make_problem(7, 4, 0.05, Drop::shell);
  MultigridSolver mg;
  ASSERT_TRUE(mg.set_matrix(pr.A, pr.view()).ok());
  int most_blocks = 0;
  for (int l = 0; l < mg.levels(); ++l) {
    ASSERT_TRUE(mg.level_is_coloured(l));
    const SparseMatrix A = mg.level_matrix(l);
    const std::vector<int> block = mg.relaxation_blocks(l);
    ASSERT_EQ(block.size(), std::size_t(A.rows()));
    most_blocks = std::max(most_blocks, *std::max_element(block.begin(), block.end()) + 1);
    int far = 0;
    for (int j = 0; j < A.outerSize(); ++j)
      for (SparseMatrix::InnerIterator it(A, j); it; ++it)
        far = std::max(far, std::abs(block[std::size_t(it.row())] - block[std::size_t(j)]));
    EXPECT_LE(far, 1) << "level " << l;
  }
  EXPECT_GE(most_blocks, 3);  // even blocks 0 and 2 relax in parallel somewhere
}

TEST(Multigrid, SerialFallbackWithoutColours) {
  Problem pr = make_problem(4, 1, 0.05, Drop::shell);
  std::vector<std::vector<std::uint8_t>> none;
  MultigridSolver mg;
  ASSERT_TRUE(mg.set_matrix(pr.A, {&pr.P, &none}).ok());
  const int top = mg.levels() - 1;
  EXPECT_FALSE(mg.level_is_coloured(top));
  std::vector<int> fwd(std::size_t(pr.A.rows()));
  for (int i = 0; i < int(fwd.size()); ++i) fwd[std::size_t(i)] = i;
  std::vector<int> rev(fwd.rbegin(), fwd.rend());
  const Eigen::MatrixXd B = random_matrix(pr.A.rows(), 2, 2);
  for (bool reverse : {false, true}) {
    Eigen::MatrixXd X = Eigen::MatrixXd::Zero(pr.A.rows(), 2), Xr = X;
    mg.gauss_seidel(top, B, X, 1, reverse);
    reference_gs(mg.level_matrix(top), B, Xr, reverse ? rev : fwd);
    EXPECT_LE((X - Xr).cwiseAbs().maxCoeff(), 1e-13 * Xr.cwiseAbs().maxCoeff());
  }
  // And the solver still converges.
  MultigridOptions opt;
  opt.cycles = 30;
  opt.tolerance = 1e-10;
  mg.set_options(opt);
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(pr.A.rows(), 2);
  EXPECT_EQ(mg.solve(B, X).status, SolveStatus::converged);
}

/// A level without colours is relaxed in blocks of consecutive rows (even blocks in parallel,
/// then odd ones; reverse: the exact reverse), each block in row order: a serial Gauss-Seidel
/// sweep in relaxation_order(), the same bits on 1 and 2 threads. The finest level of a depth-5
/// grid (35937 rows, couplings 1123 rows apart at most) has five blocks, so its order is not
/// 0..n-1 and the test can tell them apart; its coarse level (4913 rows) is one block, on the
/// single-precision compact rows.
TEST(Multigrid, LevelsWithoutColoursRelaxInBlocksOfRows) {
  Problem pr = make_problem(5, 2, 0.05);
  std::vector<std::vector<std::uint8_t>> none;
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 2);
  MultigridSolver mg;
  ASSERT_TRUE(mg.set_matrix(pr.A, {&pr.P, &none}).ok());
  const int top = mg.levels() - 1;
  ASSERT_GE(top, 1);
  for (int l : {top, top - 1}) {
    EXPECT_FALSE(mg.level_is_coloured(l));
    const SparseMatrix A = mg.level_matrix(l);
    const bool single = l < top;
    EXPECT_EQ(mg.level_has_compact_smoother(l), single) << "level " << l;
    const std::vector<int> block = mg.relaxation_blocks(l);
    const int blocks = *std::max_element(block.begin(), block.end()) + 1;
    EXPECT_EQ(blocks, l == top ? 5 : 1) << "level " << l;
    int far = 0;
    for (int j = 0; j < A.outerSize(); ++j)
      for (SparseMatrix::InnerIterator it(A, j); it; ++it)
        far = std::max(far, std::abs(block[std::size_t(it.row())] - block[std::size_t(j)]));
    EXPECT_LE(far, 1) << "level " << l;
    const std::vector<int> fwd = mg.relaxation_order(l, false);
    std::vector<int> sorted = fwd, plain(fwd.size());
    std::sort(sorted.begin(), sorted.end());
    for (int i = 0; i < int(plain.size()); ++i) plain[std::size_t(i)] = i;
    ASSERT_EQ(sorted, plain) << "not a permutation, level " << l;
    EXPECT_EQ(fwd == plain, blocks <= 2) << "level " << l;
    // The reverse sweep is the exact reverse of the forward one (blocks of one parity are
    // independent, so relaxation_order(l, true) may list them in another order).
    const std::vector<int> backward(fwd.rbegin(), fwd.rend()), rev = mg.relaxation_order(l, true);
    const Eigen::MatrixXd B = random_matrix(A.rows(), 3, 31);
    for (bool reverse : {false, true}) {
      Eigen::MatrixXd X = random_matrix(A.rows(), 3, 32), Xr = X, Xo = X, Xp = X;
      mg.gauss_seidel(l, B, X, 1, reverse);
      reference_gs(A, B, Xr, reverse ? backward : fwd, single);
      reference_gs(A, B, Xo, reverse ? rev : fwd, single);
      EXPECT_LE((X - Xo).cwiseAbs().maxCoeff(), 1e-13 * Xr.cwiseAbs().maxCoeff());
      const std::vector<int> plain_rev(plain.rbegin(), plain.rend());
      reference_gs(A, B, Xp, reverse ? plain_rev : plain, single);
      const double scale = Xr.cwiseAbs().maxCoeff();
      EXPECT_LE((X - Xr).cwiseAbs().maxCoeff(), 1e-13 * scale)
          << "level " << l << " reverse " << reverse;
      if (blocks > 2) {
        EXPECT_GT((X - Xp).cwiseAbs().maxCoeff(), 1e-6 * scale);
      }
    }
  }
  // The same bits on one thread and two, and a solver that still converges.
  MultigridOptions opt;
  opt.cycles = 3;
  const Eigen::MatrixXd B = random_matrix(pr.A.rows(), 3, 33);
  auto solve = [&](int threads) {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, threads);
    MultigridSolver m(opt);
    EXPECT_TRUE(m.set_matrix(pr.A, {&pr.P, &none}).ok());
    Eigen::MatrixXd X = Eigen::MatrixXd::Zero(pr.A.rows(), 3);
    const auto rep = m.solve(B, X);
    EXPECT_LT(rep.relative_residual, 1e-3);
    return X;
  };
  const Eigen::MatrixXd one = solve(1), two = solve(2);
  EXPECT_EQ((one - two).cwiseAbs().maxCoeff(), 0.0);
}

TEST(Multigrid, InvalidColouringFallsBackToSerial) {
  Problem pr = make_problem(3, 1, 0.05);
  for (auto& c : pr.colours.back()) c = 0;  // every function the same colour: couples
  MultigridSolver mg;
  const auto rep = mg.set_matrix(pr.A, pr.view());
  ASSERT_TRUE(rep.ok());
  EXPECT_FALSE(mg.level_is_coloured(mg.levels() - 1));
  EXPECT_TRUE(mg.level_is_coloured(0));
}

TEST(Multigrid, InvalidNonTrivialColouringStillConverges) {
  // Colour = index mod 8 couples neighbours 8 indices apart: the level is relaxed serially in
  // the internal (tile, colour, index) order, which is still a Gauss-Seidel sweep.
  Problem pr = make_problem(4, 1, 0.05, Drop::shell);
  auto& fine = pr.colours.back();
  for (std::size_t i = 0; i < fine.size(); ++i) fine[i] = std::uint8_t(i % 8);
  MultigridOptions opt;
  opt.cycles = 100;
  opt.tolerance = 1e-11;
  MultigridSolver mg(opt);
  ASSERT_TRUE(mg.set_matrix(pr.A, pr.view()).ok());
  ASSERT_FALSE(mg.level_is_coloured(mg.levels() - 1));
  const Eigen::MatrixXd B = random_matrix(pr.A.rows(), 2, 5);
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(pr.A.rows(), 2);
  EXPECT_EQ(mg.solve(B, X).status, SolveStatus::converged);
  Eigen::SimplicialLDLT<SparseMatrix> ldlt(pr.A);
  EXPECT_LT(rel_diff(X, ldlt.solve(B)), 1e-8);
}

TEST(Multigrid, ManyRightHandSidesMatchOneByOne) {
  Problem pr = make_problem(4, 1, 0.05, Drop::shell);
  MultigridOptions opt;
  opt.cycles = 2;
  MultigridSolver mg(opt);
  ASSERT_TRUE(mg.set_matrix(pr.A, pr.view()).ok());
  const Eigen::MatrixXd B = random_matrix(pr.A.rows(), 7, 4);  // chunks of 4 + 3
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(pr.A.rows(), 7);
  mg.solve(B, X);
  for (int c = 0; c < 7; ++c) {
    Eigen::MatrixXd x = Eigen::MatrixXd::Zero(pr.A.rows(), 1);
    mg.solve(B.col(c), x);
    EXPECT_LE((X.col(c) - x).cwiseAbs().maxCoeff(), 1e-13 * x.cwiseAbs().maxCoeff()) << c;
  }
}

void expect_symmetric_preconditioner(MultigridCycle cycle) {
  Problem pr = make_problem(4, 1, 0.05, Drop::shell);
  MultigridOptions opt;
  opt.cycle = cycle;
  MultigridSolver mg(opt);
  ASSERT_TRUE(mg.set_matrix(pr.A, pr.view()).ok());
  for (unsigned s = 0; s < 3; ++s) {
    const Eigen::MatrixXd u = random_matrix(pr.A.rows(), 3, 100 + s),
                          v = random_matrix(pr.A.rows(), 3, 200 + s);
    Eigen::MatrixXd Bu, Bv;
    mg.precondition(u, Bu);
    mg.precondition(v, Bv);
    for (int c = 0; c < 3; ++c) {
      const double a = u.col(c).dot(Bv.col(c)), b = v.col(c).dot(Bu.col(c));
      EXPECT_LE(std::abs(a - b), 1e-10 * u.col(c).norm() * Bv.col(c).norm()) << a << " vs " << b;
      EXPECT_GT(u.col(c).dot(Bu.col(c)), 0.0);  // positive definite
    }
  }
  // precondition == one cycle of solve from zero.
  const Eigen::MatrixXd r = random_matrix(pr.A.rows(), 3, 1);
  Eigen::MatrixXd z, X = Eigen::MatrixXd::Zero(pr.A.rows(), 3);
  mg.precondition(r, z);
  mg.solve(r, X);
  EXPECT_EQ((X - z).cwiseAbs().maxCoeff(), 0.0);
}

TEST(Multigrid, PreconditionerIsSymmetricW) {
  expect_symmetric_preconditioner(MultigridCycle::W);
}
TEST(Multigrid, PreconditionerIsSymmetricV) {
  expect_symmetric_preconditioner(MultigridCycle::V);
}

// level_work(): the visits are those of the cycle's definition (V: once per level per cycle; W:
// level l < finest 2^(finest - l) times, the coarsest as often as the next, since its exact solve
// is not repeated), counted over solve() and precondition(), cleared by reset_level_work() and by
// a new pattern; the seconds are each level's own and sum to at most the solves' wall time.
TEST(Multigrid, LevelWorkCountsTheCyclesVisits) {
  Problem pr = make_problem(5, 1, 0.05);  // 5 levels
  const Eigen::MatrixXd B = random_matrix(pr.A.rows(), 3, 11);
  for (MultigridCycle cycle : {MultigridCycle::V, MultigridCycle::W}) {
    MultigridOptions opt;
    opt.cycle = cycle;
    opt.cycles = 3;
    MultigridSolver mg(opt);
    ASSERT_TRUE(mg.set_matrix(pr.A, pr.view()).ok());
    const int top = mg.levels() - 1;
    ASSERT_EQ(top, 4);
    for (const auto& w : mg.level_work()) EXPECT_EQ(w.visits, 0);

    Eigen::MatrixXd X = Eigen::MatrixXd::Zero(pr.A.rows(), 3);
    const auto t0 = std::chrono::steady_clock::now();
    ASSERT_TRUE(mg.solve(B, X).ok());
    Eigen::MatrixXd Z;
    mg.precondition(B, Z);  // one more cycle
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    const auto work = mg.level_work();
    ASSERT_EQ(int(work.size()), top + 1);
    double total = 0;
    for (int l = 0; l <= top; ++l) {
      const std::int64_t per_cycle =
          cycle == MultigridCycle::V ? 1 : std::int64_t(1) << (top - std::max(l, 1));
      EXPECT_EQ(work[std::size_t(l)].visits, 4 * per_cycle) << to_string(cycle) << " level " << l;
      EXPECT_GT(work[std::size_t(l)].seconds, 0.0) << "level " << l;
      total += work[std::size_t(l)].seconds;
    }
    EXPECT_LE(total, wall);

    mg.reset_level_work();
    for (const auto& w : mg.level_work()) EXPECT_EQ(w.visits, 0);
    mg.precondition(B, Z);
    EXPECT_EQ(mg.level_work().back().visits, 1);
    // A new hierarchy (one level fewer) starts its own count.
    Problem coarser = make_problem(4, 1, 0.05);
    ASSERT_TRUE(mg.set_matrix(coarser.A, coarser.view()).ok());
    ASSERT_EQ(int(mg.level_work().size()), 4);
    for (const auto& w : mg.level_work()) EXPECT_EQ(w.visits, 0);
  }
}

TEST(Multigrid, SingleLevelIsADirectSolve) {
  Problem pr = make_problem(3, 3, 0.05);
  MultigridSolver mg;
  ASSERT_TRUE(mg.set_matrix(pr.A).ok());
  EXPECT_EQ(mg.levels(), 1);
  const Eigen::MatrixXd B = random_matrix(pr.A.rows(), 3, 8);
  Eigen::MatrixXd X;
  const auto rep = mg.solve(B, X);
  EXPECT_EQ(rep.status, SolveStatus::converged);
  EXPECT_LT(rep.relative_residual, 1e-12);
}

TEST(Multigrid, ReportsNotPositiveDefiniteAndFailures) {
  Problem pr = make_problem(3, 1, 0.05);
  MultigridSolver mg;
  Eigen::MatrixXd X;
  EXPECT_EQ(mg.solve(Eigen::MatrixXd::Ones(pr.A.rows(), 1), X).status, SolveStatus::failed);
  SparseMatrix neg = -pr.A;
  EXPECT_EQ(mg.set_matrix(neg, pr.view()).status, SolveStatus::not_positive_definite);
  EXPECT_EQ(mg.solve(Eigen::MatrixXd::Ones(pr.A.rows(), 1), X).status, SolveStatus::failed);
  // Indefinite but with a positive diagonal: the coarsest factorization catches it.
  double min_diag = 1e300;
  for (int i = 0; i < pr.A.rows(); ++i) min_diag = std::min(min_diag, pr.A.coeff(i, i));
  SparseMatrix id(pr.A.rows(), pr.A.rows());
  id.setIdentity();
  const SparseMatrix shifted = pr.A - 0.9 * min_diag * id;
  EXPECT_EQ(mg.set_matrix(shifted, pr.view()).status, SolveStatus::not_positive_definite);
  // Wrong hierarchy dimensions.
  std::vector<SparseMatrix> badP = {pr.P.back()};
  Problem small = make_problem(2, 1, 0.05);
  EXPECT_EQ(mg.set_matrix(small.A, {&badP, nullptr}).status, SolveStatus::failed);
  // Recovers.
  EXPECT_TRUE(mg.set_matrix(pr.A, pr.view()).ok());
  // NaN in the right-hand side.
  Eigen::MatrixXd Bn = Eigen::MatrixXd::Ones(pr.A.rows(), 1);
  Bn(3, 0) = std::nan("");
  X.resize(0, 0);
  EXPECT_EQ(mg.solve(Bn, X).status, SolveStatus::numerical_issue);
}

// LinearSolver::solve binds any column-major block without a copy (solvers/linear_solver.h).
// Every solver gives bitwise the same X for an n x 3 matrix with a fixed column count (the
// flows' Coefficients) and for a block of larger matrices (a column stride other than n) as for
// a plain MatrixXd, and leaves the entries around the block alone. A block of another shape than
// B's fails and is left as it was; a MatrixXd of another shape starts from zero.
TEST(LinearSolverInterface, AnyColumnMajorBlockSolvesInPlaceBitwise) {
  const Problem pr = make_problem(4, 1, 0.05, Drop::shell);
  const Eigen::Index n = pr.A.rows();
  const Eigen::MatrixXd B = random_matrix(n, 3, 21);
  const Eigen::MatrixXd warm = 0.1 * random_matrix(n, 3, 22);
  MultigridOptions cycle;
  cycle.cycle = MultigridCycle::W;
  cycle.cycles = 2;
  cycle.tolerance = 0.0;
  mcf::PcgOptions pcg;
  pcg.max_iterations = 6;
  pcg.relative_tolerance = 1e-14;
  std::vector<std::unique_ptr<mcf::LinearSolver>> solvers;
  solvers.push_back(std::make_unique<MultigridSolver>(cycle));
  solvers.push_back(std::make_unique<mcf::PcgSolver>(pcg));
  solvers.push_back(std::make_unique<mcf::MultigridPcgSolver>(cycle, pcg));
  solvers.push_back(std::make_unique<mcf::CholmodSolver>());
  solvers.push_back(std::make_unique<mcf::DenseLltSolver>());
  const auto bitwise = [](const auto& X, const auto& Y) {
    return X.rows() == Y.rows() && X.cols() == Y.cols() && (X.array() == Y.array()).all();
  };
  for (auto& solver : solvers) {
    SCOPED_TRACE(solver->name());
    ASSERT_TRUE(solver->set_matrix(pr.A, pr.view()).ok());
    Eigen::MatrixXd X = warm;
    const mcf::SolveReport plain = solver->solve(B, X);
    ASSERT_TRUE(plain.ok()) << plain.message;
    ASSERT_FALSE(bitwise(X, warm));  // it solved something

    Eigen::Matrix<double, Eigen::Dynamic, 3> Bc = B, Xc = warm;
    const mcf::SolveReport fixed = solver->solve(Bc, Xc);
    EXPECT_TRUE(fixed.ok());
    EXPECT_TRUE(bitwise(Xc, X));
    EXPECT_EQ(fixed.relative_residual, plain.relative_residual);

    // Rows 2..n+1 and columns 1..3 of (n + 5) x 5 matrices: the column stride is n + 5.
    Eigen::MatrixXd Bw = Eigen::MatrixXd::Constant(n + 5, 5, 7.0),
                    Xw = Eigen::MatrixXd::Constant(n + 5, 5, -3.0);
    Bw.block(2, 1, n, 3) = B;
    Xw.block(2, 1, n, 3) = warm;
    const mcf::SolveReport strided = solver->solve(Bw.block(2, 1, n, 3), Xw.block(2, 1, n, 3));
    EXPECT_TRUE(strided.ok());
    EXPECT_TRUE(bitwise(Eigen::MatrixXd(Xw.block(2, 1, n, 3)), X));
    EXPECT_EQ(strided.relative_residual, plain.relative_residual);
    Eigen::MatrixXd around = Xw;
    around.block(2, 1, n, 3).setConstant(-3.0);
    EXPECT_TRUE((around.array() == -3.0).all());

    // Another shape: a block fails untouched; a resizable matrix is zeroed, then solved.
    Eigen::Matrix<double, Eigen::Dynamic, 3> short_block =
        Eigen::Matrix<double, Eigen::Dynamic, 3>::Constant(n - 1, 3, 5.0);
    const mcf::SolveReport refused = solver->solve(B, short_block);
    EXPECT_EQ(refused.status, SolveStatus::failed);
    EXPECT_NE(refused.message.find("warm start"), std::string::npos) << refused.message;
    EXPECT_TRUE((short_block.array() == 5.0).all());
    Eigen::MatrixXd zero = Eigen::MatrixXd::Zero(n, 3), resized(n - 1, 2);
    ASSERT_TRUE(solver->solve(B, zero).ok());
    ASSERT_TRUE(solver->solve(B, resized).ok());
    EXPECT_TRUE(bitwise(resized, zero));
  }
}

}  // namespace

// --- FallbackMultigridSolver (solvers/multigrid_fallback.h) ---

namespace {

TEST(MultigridFallback, ContractionIsTheMeanReductionFromTheWarmStart) {
  Problem pr = make_problem(4, 1, 0.05);
  MultigridOptions o;
  o.cycles = 3;
  o.measure_contraction = true;
  MultigridSolver mg(o);
  ASSERT_TRUE(mg.set_matrix(pr.A, pr.view()).ok());
  const Eigen::MatrixXd B = random_matrix(pr.A.rows(), 3, 5);
  Eigen::MatrixXd X = 0.5 * random_matrix(pr.A.rows(), 3, 6);
  const double r0 =
      ((B - pr.A * X).colwise().norm().array() / B.colwise().norm().array()).maxCoeff();
  const auto rep = mg.solve(B, X);
  ASSERT_EQ(rep.iterations, 3);
  EXPECT_NEAR(rep.contraction, std::pow(rep.relative_residual / r0, 1.0 / 3), 1e-9);
  EXPECT_GT(rep.contraction, 0.0);
  EXPECT_LT(rep.contraction, 0.5);
  // Not measured unless asked (or a tolerance needs it).
  MultigridSolver plain;
  ASSERT_TRUE(plain.set_matrix(pr.A, pr.view()).ok());
  Eigen::MatrixXd Y = Eigen::MatrixXd::Zero(pr.A.rows(), 3);
  EXPECT_EQ(plain.solve(B, Y).contraction, -1);
}

TEST(MultigridFallback, ContractingCyclesAreTheMultigridsOwnBits) {
  Problem pr = make_problem(4, 1, 0.05);
  MultigridOptions o;
  o.cycles = 2;
  MultigridSolver mg(o);
  mcf::FallbackMultigridSolver guarded(o, {});
  ASSERT_TRUE(mg.set_matrix(pr.A, pr.view()).ok());
  ASSERT_TRUE(guarded.set_matrix(pr.A, pr.view()).ok());
  const Eigen::MatrixXd B = random_matrix(pr.A.rows(), 3, 8);
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(pr.A.rows(), 3), Y = X;
  const auto a = mg.solve(B, X), b = guarded.solve(B, Y);
  EXPECT_EQ(X, Y);
  EXPECT_EQ(a.residuals, b.residuals);
  EXPECT_EQ(b.fallback_iterations, 0);
  EXPECT_EQ(guarded.fallbacks(), 0);
}

TEST(MultigridFallback, StalledCyclesHandOverToCgThatReachesTheTolerance) {
  Problem pr = make_problem(4, 1, 0.05);
  Eigen::SimplicialLDLT<SparseMatrix> ldlt(pr.A);
  const Eigen::MatrixXd B = random_matrix(pr.A.rows(), 3, 9);
  const Eigen::MatrixXd exact = ldlt.solve(B);
  MultigridOptions o;  // one W-cycle: contracts by ~0.05, "stalled" for a bound of 1e-12
  mcf::StallFallbackOptions f;
  f.stall_ratio = 1e-12;
  f.tolerance = 1e-11;
  f.direct_after = 0;  // CG alone here; the factorization after it is tested below
  mcf::FallbackMultigridSolver guarded(o, f);
  for (int round = 0; round < 2; ++round) {  // the second solve reuses CG's matrix
    ASSERT_TRUE(guarded.set_matrix(pr.A, pr.view()).ok());
    Eigen::MatrixXd X = Eigen::MatrixXd::Zero(pr.A.rows(), 3);
    const auto rep = guarded.solve(B, X);
    EXPECT_EQ(rep.status, SolveStatus::converged);
    EXPECT_GT(rep.fallback_iterations, 0);
    EXPECT_EQ(rep.iterations, 1 + rep.fallback_iterations);
    EXPECT_EQ(int(rep.residuals.size()), rep.iterations);
    EXPECT_LE(rep.relative_residual, 1e-11);
    EXPECT_LT(rel_diff(X, exact), 1e-8);
    EXPECT_NE(rep.message.find("stalled"), std::string::npos);
    EXPECT_EQ(guarded.fallbacks(), round + 1);
  }
  // A bound above the floor: CG stops where healthy cycles would have been, r_0 · bound^k (r_0 = 1
  // from a zero start), not at the floor.
  // The bound is a tenth of what the cycle achieves, so it counts as stalled.
  MultigridOptions measured = o;
  measured.measure_contraction = true;
  MultigridSolver plain(measured);
  ASSERT_TRUE(plain.set_matrix(pr.A, pr.view()).ok());
  Eigen::MatrixXd Z = Eigen::MatrixXd::Zero(pr.A.rows(), 3);
  const double bound = 0.1 * plain.solve(B, Z).contraction;
  ASSERT_GT(bound, 1e-6);
  f.stall_ratio = bound;
  mcf::FallbackMultigridSolver to_bound(o, f);
  ASSERT_TRUE(to_bound.set_matrix(pr.A, pr.view()).ok());
  {
    Eigen::MatrixXd X = Eigen::MatrixXd::Zero(pr.A.rows(), 3);
    const auto rep = to_bound.solve(B, X);
    EXPECT_GT(rep.fallback_iterations, 0);
    EXPECT_LE(rep.relative_residual, bound * (1 + 1e-9));
    EXPECT_GT(rep.relative_residual, 1e-3 * bound);  // stopped near the bound, not at the floor
  }
  // CG that runs out of iterations says so: not converged, not silently exact.
  f.stall_ratio = 1e-12;
  f.max_iterations = 1;
  f.tolerance = 1e-15;
  mcf::FallbackMultigridSolver capped(o, f);
  ASSERT_TRUE(capped.set_matrix(pr.A, pr.view()).ok());
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(pr.A.rows(), 3);
  EXPECT_EQ(capped.solve(B, X).status, SolveStatus::max_iterations);
}

// The residual bound: contracting cycles that end above it run a few more V(2,2)-cycles (cheaper
// than the configured W(5,5)-cycle), which are the plain multigrid's own V(2,2)-cycles from where
// its cycles ended bit for bit, and the step is converged at the bound.
TEST(MultigridFallback, ContractingCyclesAboveTheBoundRunMoreCyclesToIt) {
  Problem pr = make_problem(4, 1, 0.05);
  const Eigen::MatrixXd B = random_matrix(pr.A.rows(), 3, 21);
  MultigridOptions o;
  o.cycles = 2;
  o.measure_contraction = true;
  ASSERT_EQ(o.cycle, mcf::MultigridCycle::W);
  ASSERT_GT(o.pre_smooth, mcf::kExtraCycleSweeps);
  MultigridSolver plain(o);
  ASSERT_TRUE(plain.set_matrix(pr.A, pr.view()).ok());
  Eigen::MatrixXd X2 = Eigen::MatrixXd::Zero(pr.A.rows(), 3);
  const mcf::SolveReport two = plain.solve(B, X2);
  ASSERT_EQ(two.status, SolveStatus::max_iterations);  // fixed work: nothing checked
  ASSERT_GT(two.contraction, 0.0);
  ASSERT_LT(two.contraction, 0.5);
  // One V(2,2)-cycle from there: its reduction q, weaker than the W(5,5)-cycle's.
  MultigridOptions v = o;
  v.cycle = mcf::MultigridCycle::V;
  v.pre_smooth = v.post_smooth = mcf::kExtraCycleSweeps;
  v.cycles = 1;
  plain.set_options(v);
  Eigen::MatrixXd X3 = X2;
  const mcf::SolveReport one_v = plain.solve(B, X3);
  const double q = one_v.relative_residual / two.relative_residual;
  ASSERT_GT(q, two.contraction);
  ASSERT_LT(q, 0.5);
  // A bound one and a half V-cycle reductions below where the two cycles end: two more reach
  // it (the W-cycles' mean contraction, which the guard predicts with, says one or two).
  const double bound = two.relative_residual * std::pow(q, 1.5);
  mcf::StallFallbackOptions f;
  f.residual_bound = bound;
  mcf::FallbackMultigridSolver guarded(o, f);
  ASSERT_TRUE(guarded.set_matrix(pr.A, pr.view()).ok());
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(pr.A.rows(), 3);
  const mcf::SolveReport rep = guarded.solve(B, X);
  EXPECT_EQ(rep.status, SolveStatus::converged);
  EXPECT_LE(rep.relative_residual, bound);
  ASSERT_EQ(rep.extra_cycles, 2);
  EXPECT_EQ(rep.fallback_iterations, 0);
  EXPECT_FALSE(rep.direct_fallback);
  EXPECT_EQ(rep.iterations, 2 + rep.extra_cycles);
  EXPECT_EQ(int(rep.residuals.size()), rep.iterations);
  EXPECT_EQ(guarded.fallbacks(), 1);
  EXPECT_NE(rep.message.find("above the residual bound"), std::string::npos) << rep.message;
  // The same iterate as the plain multigrid's two W(5,5)-cycles, then two V(2,2)-cycles.
  v.cycles = 2;
  plain.set_options(v);
  Eigen::MatrixXd Y = X2;
  const mcf::SolveReport then = plain.solve(B, Y);
  EXPECT_EQ(X, Y);
  EXPECT_EQ(rep.residuals[2], then.residuals[0]);
  EXPECT_EQ(rep.residuals[3], then.residuals[1]);
  plain.set_options(o);
  // Cycles under the bound are converged as they are; with no bound, fixed work is unchecked.
  f.residual_bound = 10 * two.relative_residual;
  mcf::FallbackMultigridSolver loose(o, f);
  ASSERT_TRUE(loose.set_matrix(pr.A, pr.view()).ok());
  Eigen::MatrixXd Z = Eigen::MatrixXd::Zero(pr.A.rows(), 3);
  const mcf::SolveReport under = loose.solve(B, Z);
  EXPECT_EQ(under.status, SolveStatus::converged);
  EXPECT_EQ(under.extra_cycles, 0);
  EXPECT_EQ(Z, X2);
  f.residual_bound = 0;
  mcf::FallbackMultigridSolver unbound(o, f);
  ASSERT_TRUE(unbound.set_matrix(pr.A, pr.view()).ok());
  Z.setZero();
  EXPECT_EQ(unbound.solve(B, Z).status, SolveStatus::max_iterations);
}

// A step whose start fit the caller's prediction (a smooth stretch of a flow) keeps its
// contracting cycles' answer above the bound and says so; without a fit, with a poor one, or with
// bound_smooth_steps it continues to the bound. The hint holds for one solve only.
TEST(MultigridFallback, SmoothStepsKeepTheirCyclesAboveTheBoundAndSaySo) {
  Problem pr = make_problem(4, 1, 0.05);
  const Eigen::MatrixXd B = random_matrix(pr.A.rows(), 3, 24);
  MultigridOptions o;  // one W-cycle from zero: contracting, far above 1e-8
  mcf::StallFallbackOptions f;
  f.residual_bound = 1e-8;
  f.direct_after = 0;
  mcf::FallbackMultigridSolver guarded(o, f);
  ASSERT_TRUE(guarded.set_matrix(pr.A, pr.view()).ok());
  MultigridSolver plain(o);
  ASSERT_TRUE(plain.set_matrix(pr.A, pr.view()).ok());
  Eigen::MatrixXd cycles = Eigen::MatrixXd::Zero(pr.A.rows(), 3);
  const mcf::SolveReport fixed = plain.solve(B, cycles);
  ASSERT_GT(fixed.relative_residual, 1e3 * f.residual_bound);

  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(pr.A.rows(), 3);
  guarded.set_start_fit(mcf::kSmoothStartFit);
  const mcf::SolveReport kept = guarded.solve(B, X);
  EXPECT_EQ(kept.status, SolveStatus::max_iterations);  // not converged: above the bound
  EXPECT_EQ(kept.relative_residual, fixed.relative_residual);
  EXPECT_EQ(kept.iterations, 1);
  EXPECT_EQ(kept.extra_cycles + kept.fallback_iterations, 0);
  EXPECT_EQ(X, cycles);
  EXPECT_NE(kept.message.find("kept: a smooth step"), std::string::npos) << kept.message;

  // The next solve has no fit: held to the bound.
  X.setZero();
  const mcf::SolveReport held = guarded.solve(B, X);
  EXPECT_EQ(held.status, SolveStatus::converged);
  EXPECT_LE(held.relative_residual, f.residual_bound);
  // A poor fit: held to the bound.
  X.setZero();
  guarded.set_start_fit(0.9 * mcf::kSmoothStartFit);
  EXPECT_EQ(guarded.solve(B, X).status, SolveStatus::converged);
  // bound_smooth_steps: every step held.
  f.bound_smooth_steps = true;
  mcf::FallbackMultigridSolver strict(o, f);
  ASSERT_TRUE(strict.set_matrix(pr.A, pr.view()).ok());
  X.setZero();
  strict.set_start_fit(1.0);
  const mcf::SolveReport all = strict.solve(B, X);
  EXPECT_EQ(all.status, SolveStatus::converged);
  EXPECT_LE(all.relative_residual, f.residual_bound);
}

// A bound a few cycles cannot reach goes to CG by the cycle, whose target is the bound (not the
// stall target, nor the fallback tolerance below it).
TEST(MultigridFallback, ABoundFarBelowTheCyclesIsReachedByCg) {
  Problem pr = make_problem(4, 1, 0.05);
  const Eigen::MatrixXd B = random_matrix(pr.A.rows(), 3, 22);
  const Eigen::MatrixXd exact = Eigen::SimplicialLDLT<SparseMatrix>(pr.A).solve(B);
  MultigridOptions o;  // one W-cycle from zero: far above 1e-12
  mcf::StallFallbackOptions f;
  f.residual_bound = 1e-12;
  f.tolerance = 1e-13;
  f.direct_after = 0;
  mcf::FallbackMultigridSolver guarded(o, f);
  ASSERT_TRUE(guarded.set_matrix(pr.A, pr.view()).ok());
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(pr.A.rows(), 3);
  const mcf::SolveReport rep = guarded.solve(B, X);
  EXPECT_EQ(rep.status, SolveStatus::converged);
  EXPECT_GT(rep.fallback_iterations, 0);
  EXPECT_EQ(rep.extra_cycles, 0);  // 1e-12 is more than max(2, 1) cycles away
  EXPECT_LE(rep.relative_residual, 1e-12);
  EXPECT_LT(rel_diff(X, exact), 1e-9);
  EXPECT_NE(rep.message.find("CG preconditioned by the cycle took over to 1e-12"),
            std::string::npos)
      << rep.message;
}

// With a tolerance, give_up_ratio stops at the first cycle that reduces the residual by less.
TEST(Multigrid, GiveUpRatioStopsAtACycleThatReducesTooLittle) {
  Problem pr = make_problem(4, 1, 0.05);
  const Eigen::MatrixXd B = random_matrix(pr.A.rows(), 3, 23);
  MultigridOptions o;
  o.cycles = 10;
  o.tolerance = 1e-14;
  o.give_up_ratio = 1e-9;  // no cycle reduces the residual a billionfold
  MultigridSolver mg(o);
  ASSERT_TRUE(mg.set_matrix(pr.A, pr.view()).ok());
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(pr.A.rows(), 3);
  const mcf::SolveReport rep = mg.solve(B, X);
  EXPECT_EQ(rep.iterations, 1);
  EXPECT_EQ(rep.status, SolveStatus::max_iterations);
  EXPECT_NE(rep.message.find("stopped"), std::string::npos);
  o.give_up_ratio = 0.9;  // every W-cycle here reduces it far more
  mg.set_options(o);
  X.setZero();
  const mcf::SolveReport on = mg.solve(B, X);
  EXPECT_EQ(on.status, SolveStatus::converged);
  EXPECT_GT(on.iterations, 3);
}

TEST(MultigridFallback, CgThatRunsOutHandsTheStepToTheFactorizationAndLaterStallsGoThereAtOnce) {
  Problem pr = make_problem(4, 1, 0.05);
  const Eigen::MatrixXd B = random_matrix(pr.A.rows(), 3, 11);
  MultigridOptions o;
  mcf::StallFallbackOptions f;
  f.stall_ratio = 1e-12;  // every solve stalls
  f.tolerance = 1e-15;    // out of CG's reach in 2 iterations
  f.direct_after = 2;
  mcf::FallbackMultigridSolver guarded(o, f);
  // Two matrices on one pattern: the factor must follow set_matrix.
  const SparseMatrix A2 = make_problem(4, 1, 0.3).A;
  ASSERT_EQ(A2.nonZeros(), pr.A.nonZeros());
  for (int round = 0; round < 3; ++round) {
    const SparseMatrix& A = round == 1 ? A2 : pr.A;
    ASSERT_TRUE(guarded.set_matrix(A, pr.view()).ok());
    const Eigen::MatrixXd exact = Eigen::SimplicialLDLT<SparseMatrix>(A).solve(B);
    Eigen::MatrixXd X = Eigen::MatrixXd::Zero(A.rows(), 3);
    const auto rep = guarded.solve(B, X);
    EXPECT_EQ(rep.status, SolveStatus::converged);
    EXPECT_TRUE(rep.direct_fallback);
    EXPECT_LT(rel_diff(X, exact), 1e-10);
    EXPECT_LT(rep.relative_residual, 1e-12);
    EXPECT_EQ(rep.residuals.back(), rep.relative_residual);
    // The first stalled solve tries CG for its 2 iterations; later ones go to the factor at once.
    EXPECT_EQ(rep.fallback_iterations, round == 0 ? 2 : 0);
    EXPECT_EQ(rep.iterations, 1 + rep.fallback_iterations);
    EXPECT_NE(rep.message.find("factorization solved it"), std::string::npos) << rep.message;
    EXPECT_EQ(guarded.direct_solves(), round + 1);
    EXPECT_EQ(guarded.fallbacks(), round + 1);
  }
  // Contracting cycles never touch the factorization, however it was used before.
  mcf::StallFallbackOptions healthy = f;
  healthy.stall_ratio = 0.9;
  mcf::FallbackMultigridSolver fine(o, healthy);
  ASSERT_TRUE(fine.set_matrix(pr.A, pr.view()).ok());
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(pr.A.rows(), 3);
  EXPECT_FALSE(fine.solve(B, X).direct_fallback);
  EXPECT_EQ(fine.direct_solves(), 0);
}

TEST(MultigridFallback, AMatrixThatIsNotDefiniteFailsTheStepAsAFactorizationWould) {
  // A - c v v^T for the checkerboard v on the interior functions: v^T A v < 0, so A is not
  // definite, but the trilinear restriction nearly annihilates v (exactly, away from the
  // boundary), so the coarse levels stay definite and the multigrid accepts the matrix. The
  // cycles do not contract, CG breaks down or runs out, and the factorization meets a non-positive
  // pivot: the step fails and says why, with or without the factorization.
  Problem pr = make_problem(3, 1, 0.05);
  const int N = 8;
  Eigen::VectorXd v = Eigen::VectorXd::Zero(pr.A.rows());
  for (int k = 1; k < N; ++k)
    for (int j = 1; j < N; ++j)
      for (int i = 1; i < N; ++i) v[vid(N, i, j, k)] = ((i + j + k) & 1) ? -1.0 : 1.0;
  const double c = 2 * v.dot(pr.A * v) / (v.squaredNorm() * v.squaredNorm());
  const SparseMatrix A = (Eigen::MatrixXd(pr.A) - c * v * v.transpose()).sparseView();
  ASSERT_LT(v.dot(A * v), 0);
  const Eigen::MatrixXd B = random_matrix(A.rows(), 2, 12);
  for (const int direct_after : {0, 10}) {
    mcf::StallFallbackOptions f;
    f.direct_after = direct_after;
    mcf::FallbackMultigridSolver guarded(MultigridOptions{}, f);
    const auto set = guarded.set_matrix(A, pr.view());
    ASSERT_TRUE(set.ok()) << set.message;
    Eigen::MatrixXd X = Eigen::MatrixXd::Zero(A.rows(), 2);
    const auto rep = guarded.solve(B, X);
    EXPECT_FALSE(rep.ok()) << mcf::to_string(rep.status) << ": " << rep.message;
    EXPECT_FALSE(rep.direct_fallback);
    EXPECT_EQ(guarded.direct_solves(), 0);
    if (direct_after > 0) {
      EXPECT_EQ(rep.status, SolveStatus::not_positive_definite);
      EXPECT_NE(rep.message.find("factorization failed"), std::string::npos) << rep.message;
    }
  }
}

}  // namespace
