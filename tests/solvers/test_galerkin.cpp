// The Galerkin product's plan (solvers/galerkin.h): values through the plan's local slots are
// bitwise those of the dense accumulator, both equal Pᵀ A P formed by Eigen, and a plan that would
// outgrow A is not made. PETSc's product (solvers/petsc_galerkin.h) gives the same values, also
// after a refresh of A's values.

#include "core/galerkin_pattern.h"
#include "solvers/galerkin.h"
#include "solvers/petsc_galerkin.h"
#include "solvers/petsc_runtime.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <numeric>
#include <random>

namespace mcf::multigrid_detail {
namespace {

/// A symmetric positive matrix on an n x n grid's 9-point stencil with random values, and a
/// prolongation from every other grid point whose rows take 1 to 3 random coarse neighbours.
struct Product {
  SparseMatrix A, P, PT, C;
  std::vector<int> transpose_pos, order;
};

Product make_product(int n, unsigned seed, int parents = 3) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.1, 1.0);
  Product g;
  const int N = n * n;
  std::vector<Eigen::Triplet<double>> t;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x)
      for (int dy = 0; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          if (dy == 0 && dx <= 0) continue;
          const int x2 = x + dx, y2 = y + dy;
          if (x2 < 0 || x2 >= n || y2 >= n) continue;
          const double v = -u(rng);
          t.emplace_back(y * n + x, y2 * n + x2, v);
          t.emplace_back(y2 * n + x2, y * n + x, v);
        }
  for (int i = 0; i < N; ++i) t.emplace_back(i, i, 10.0);
  g.A.resize(N, N);
  g.A.setFromTriplets(t.begin(), t.end());
  g.A.makeCompressed();
  const int nc = (n / 2) * (n / 2);
  t.clear();
  std::uniform_int_distribution<int> count(1, parents);
  for (int i = 0; i < N; ++i) {
    const int y = std::min(i / n / 2, n / 2 - 1), x = std::min(i % n / 2, n / 2 - 1);
    std::vector<int> cols = {y * (n / 2) + x};
    // Further parents from the coarse neighbourhood, as wide as needed for k distinct ones.
    const int k = std::min(count(rng), nc);
    for (int reach = 1; int(cols.size()) < k; ++reach)
      for (int tries = 0; tries < 8 && int(cols.size()) < k; ++tries) {
        std::uniform_int_distribution<int> step(-reach, reach);
        const int c = std::clamp(cols[0] + step(rng) + step(rng) * (n / 2), 0, nc - 1);
        if (std::find(cols.begin(), cols.end(), c) == cols.end()) cols.push_back(c);
      }
    for (int c : cols) t.emplace_back(i, c, u(rng));
  }
  g.P.resize(N, nc);
  g.P.setFromTriplets(t.begin(), t.end());
  g.P.makeCompressed();
  g.PT = SparseMatrix(g.P.transpose());
  g.PT.makeCompressed();
  g.C = galerkin_pattern(g.P, g.A);
  g.transpose_pos = transpose_positions(g.C);
  g.order.resize(std::size_t(nc));
  std::iota(g.order.begin(), g.order.end(), 0);
  std::shuffle(g.order.begin(), g.order.end(), rng);
  return g;
}

/// max |X - Y| over max |Y|, entry by entry (patterns may differ by explicit zeros).
double relative_max_difference(const SparseMatrix& X, const SparseMatrix& Y) {
  return (Eigen::MatrixXd(X) - Eigen::MatrixXd(Y)).cwiseAbs().maxCoeff() /
         Eigen::MatrixXd(Y).cwiseAbs().maxCoeff();
}

TEST(Galerkin, PlannedValuesAreBitwiseTheDenseOnesAndEqualPTAP) {
  for (int threads : {1, 2}) {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
    for (const bool shuffled : {false, true}) {
      Product g = make_product(60, 7);
      const std::vector<int> order = shuffled ? g.order : std::vector<int>{};
      const GalerkinPlan plan = galerkin_plan(Csc(g.A), g.P, g.C, order);
      ASSERT_FALSE(plan.empty());
      EXPECT_LE(plan.bytes(), std::size_t(g.A.nonZeros()) * 12 + 24 * std::size_t(g.P.cols() + 1) +
                                  2 * std::size_t(g.P.cols()));
      std::vector<double> dense(std::size_t(g.C.nonZeros())), planned(dense.size());
      Spa spa1, spa2;
      galerkin_values(Csc(g.A), g.P, g.C, dense.data(), g.transpose_pos, order, spa1);
      galerkin_values(Csc(g.A), g.P, g.C, planned.data(), g.transpose_pos, order, spa2, &plan);
      EXPECT_EQ(dense, planned) << "threads " << threads << " shuffled " << shuffled;
      // Against Eigen's product on the same pattern.
      const SparseMatrix ref = SparseMatrix(g.PT * g.A * g.P);
      SparseMatrix C = g.C;
      std::copy(planned.begin(), planned.end(), C.valuePtr());
      EXPECT_LE(relative_max_difference(C, ref), 1e-12);
      // A second call on changed values, through the same plan.
      for (int k = 0; k < g.A.nonZeros(); ++k) g.A.valuePtr()[k] *= 1.0 + 1e-3 * (k % 7);
      galerkin_values(Csc(g.A), g.P, g.C, dense.data(), g.transpose_pos, order, spa1);
      galerkin_values(Csc(g.A), g.P, g.C, planned.data(), g.transpose_pos, order, spa2, &plan);
      EXPECT_EQ(dense, planned);
    }
  }
}

TEST(Galerkin, NoPlanWhereItWouldOutgrowTheMatrix) {
  // Dense prolongation rows (every fine function takes 40 coarse parents): the plan's terms far
  // exceed A's entries, so none is made, and the dense path still gives Pᵀ A P.
  Product g = make_product(20, 3, 40);
  const GalerkinPlan plan = galerkin_plan(Csc(g.A), g.P, g.C, {});
  EXPECT_TRUE(plan.empty());
  std::vector<double> values(std::size_t(g.C.nonZeros()));
  Spa spa;
  galerkin_values(Csc(g.A), g.P, g.C, values.data(), g.transpose_pos, {}, spa, &plan);
  SparseMatrix C = g.C;
  std::copy(values.begin(), values.end(), C.valuePtr());
  EXPECT_LE(relative_max_difference(C, SparseMatrix(g.PT * g.A * g.P)), 1e-12);
}

TEST(PetscGalerkin, MatPtAPGivesTheMultigridsValuesAlsoAfterARefresh) {
  if (!petsc_available()) GTEST_SKIP() << "built without PETSc";
  Product g = make_product(40, 5);
  const GalerkinPlan plan = galerkin_plan(Csc(g.A), g.P, g.C, g.order);
  Spa spa;
  const auto ours = [&] {
    SparseMatrix C = g.C;
    galerkin_values(Csc(g.A), g.P, g.C, C.valuePtr(), g.transpose_pos, g.order, spa, &plan);
    return C;
  };
  const SparseMatrix A0 = g.A;
  for (const char* algorithm : {"default", "rap", "hypre"}) {
    g.A = A0;
    PetscGalerkin petsc(g.A, g.P, algorithm);
    EXPECT_LE(relative_max_difference(petsc.product(), ours()), 1e-13) << algorithm;
    // New values on A's pattern (still symmetric): the product follows them.
    for (int j = 0; j < g.A.outerSize(); ++j)
      for (SparseMatrix::InnerIterator it(g.A, j); it; ++it)
        it.valueRef() *= 1.0 + 0.1 * double((it.row() + it.col()) % 5);
    const SparseMatrix before = petsc.product();
    petsc.refresh(g.A.valuePtr());
    EXPECT_GT(relative_max_difference(before, ours()), 1e-3) << algorithm;
    EXPECT_LE(relative_max_difference(petsc.product(), ours()), 1e-13) << algorithm;
  }
  EXPECT_THROW(PetscGalerkin(A0, g.P, "no-such-algorithm"), PetscFailure);
}

}  // namespace
}  // namespace mcf::multigrid_detail
