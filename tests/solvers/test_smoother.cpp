// The smoother's sweep (solvers/smoother.h, gauss_seidel_sweep) on one level set up from its parts
// as the multigrid solver sets up its levels (internal numbering, relaxation blocks, diagonal,
// smoother rows): each variant of the rows it reads (the CSC matrix, a coarse level's compact
// single-precision rows, the finest level's aligned rows) on a coloured level and on one without
// colours equals the serial Gauss-Seidel sweep in the order relaxation_order() lists (forward, and
// reverse in the exact reverse order), and gives the same bits on 1 and 2 threads.
// The solver's own sweeps are tested through MultigridSolver in test_multigrid.cpp.

#include "solvers/smoother.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <Eigen/Dense>

#include <cstdint>
#include <random>
#include <vector>

namespace mcf::multigrid_detail {
namespace {

/// A symmetric, diagonally dominant matrix on an n x n grid's 9-point stencil with random values
/// (couplings n + 1 rows apart at most), and the grid's parity colours (neighbours differ).
struct Grid {
  SparseMatrix A;
  std::vector<std::uint8_t> colours;
};

Grid make_grid(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.1, 1.0);
  std::vector<Eigen::Triplet<double>> t;
  const int N = n * n;
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
  for (int i = 0; i < N; ++i) t.emplace_back(i, i, 9.0 + u(rng));
  Grid g;
  g.A.resize(N, N);
  g.A.setFromTriplets(t.begin(), t.end());
  g.A.makeCompressed();
  g.colours.resize(std::size_t(N));
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x)
      g.colours[std::size_t(y * n + x)] = std::uint8_t((x & 1) | (y & 1) << 1);
  return g;
}

enum class Rows { csc, compact, aligned };

/// One level as MultigridState::symbolic and numeric set it up (solvers/multigrid_setup.cpp).
struct Level {
  LevelNumbering L;
  SparseMatrix A;  // internal numbering
  std::vector<int> diag_pos;
  std::vector<double> inv_diag;
  SmootherRows S;
};

Level make_level(const Grid& g, bool coloured, Rows rows) {
  Level v;
  const int n = int(g.A.rows());
  const std::vector<std::uint8_t>* colours = coloured ? &g.colours : nullptr;
  number_by_colour(v.L, n, colours);
  // The finest level keeps the caller's order within columns and stores the diagonal last; a
  // coarse level's columns are sorted.
  v.A = permuted(g.A, v.L.inv, v.L.perm, rows != Rows::aligned);
  if (rows == Rows::aligned) diagonal_last(v.A);
  check_colouring(v.L, v.A, colours);
  find_blocks(v.L, v.A);
  v.diag_pos = diagonal_positions(v.A);
  v.inv_diag.resize(std::size_t(n));
  for (int i = 0; i < n; ++i)
    v.inv_diag[std::size_t(i)] = 1.0 / v.A.valuePtr()[v.diag_pos[std::size_t(i)]];
  if (rows != Rows::csc) {
    v.S = smoother_pattern(v.A, v.diag_pos, rows == Rows::aligned);
    smoother_values(v.S, v.A, v.diag_pos);
  }
  return v;
}

/// `sweeps` sweeps of gauss_seidel_sweep on B's columns from X (caller's numbering), k <= 4.
Eigen::MatrixXd sweep(const Level& v, const Eigen::MatrixXd& B, Eigen::MatrixXd X, bool reverse,
                      int sweeps) {
  const int n = int(B.rows());
  const std::size_t s = 4;
  std::vector<double> b(std::size_t(n) * s, 0.0), x(b.size(), 0.0);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < B.cols(); ++c) {
      b[std::size_t(r) * s + std::size_t(c)] = B(old_index(v.L.perm, r), c);
      x[std::size_t(r) * s + std::size_t(c)] = X(old_index(v.L.perm, r), c);
    }
  for (int i = 0; i < sweeps; ++i)
    gauss_seidel_sweep(v.L, Csc(v.A), v.S, v.diag_pos.data(), v.inv_diag.data(), b.data(), x.data(),
                       s, reverse);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < X.cols(); ++c)
      X(old_index(v.L.perm, r), c) = x[std::size_t(r) * s + std::size_t(c)];
  return X;
}

/// Serial Gauss-Seidel on A (caller's numbering) in `order`; `single`: the off-diagonal values
/// rounded to single precision, as the compact rows hold them.
void reference_sweep(const SparseMatrix& A, const Eigen::MatrixXd& B, Eigen::MatrixXd& X,
                     const std::vector<int>& order, bool single) {
  for (int i : order)
    for (int c = 0; c < B.cols(); ++c) {
      double sum = B(i, c), diagonal = 0.0;
      for (SparseMatrix::InnerIterator it(A, i); it; ++it) {
        if (it.row() == i) {
          diagonal = it.value();
          continue;
        }
        const double a = single ? double(float(it.value())) : it.value();
        sum -= a * X(it.row(), c);
      }
      X(i, c) = sum * (1.0 / diagonal);
    }
}

Eigen::MatrixXd random_matrix(int n, int k, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> N01;
  Eigen::MatrixXd M(n, k);
  for (int c = 0; c < k; ++c)
    for (int i = 0; i < n; ++i) M(i, c) = N01(rng);
  return M;
}

TEST(Smoother, SweepIsTheSerialGaussSeidelInItsRelaxationOrderOnAnyThreadCount) {
  // 200 x 200 functions: 40 tiles, several relaxation blocks with or without colours, so blocks
  // of one parity are relaxed in parallel.
  const Grid g = make_grid(200, 5);
  const int n = int(g.A.rows());
  const Eigen::MatrixXd B = random_matrix(n, 3, 1), X0 = random_matrix(n, 3, 2);
  for (const bool coloured : {true, false})
    for (const Rows rows : {Rows::csc, Rows::compact, Rows::aligned}) {
      if (!coloured && rows == Rows::aligned) continue;  // the solver reads CSC rows there
      const Level v = make_level(g, coloured, rows);
      const std::string what = std::string(coloured ? "coloured" : "without colours") + ", rows " +
                               std::to_string(int(rows));
      ASSERT_EQ(v.L.coloured, coloured) << what;
      ASSERT_GE(v.L.blocks(), 3) << what;
      ASSERT_EQ(v.S.empty(), rows == Rows::csc) << what;
      const std::vector<int> fwd = relaxation_order(v.L, n, false);
      for (const bool reverse : {false, true}) {
        Eigen::MatrixXd one, two;
        {
          tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 1);
          one = sweep(v, B, X0, reverse, 2);
        }
        {
          tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 2);
          two = sweep(v, B, X0, reverse, 2);
        }
        EXPECT_TRUE(one == two) << what << ", reverse " << reverse;
        Eigen::MatrixXd ref = X0;
        const std::vector<int> order = reverse ? std::vector<int>(fwd.rbegin(), fwd.rend()) : fwd;
        for (int i = 0; i < 2; ++i) reference_sweep(g.A, B, ref, order, rows == Rows::compact);
        EXPECT_LE((two - ref).cwiseAbs().maxCoeff(), 1e-13 * ref.cwiseAbs().maxCoeff())
            << what << ", reverse " << reverse;
      }
    }
}

}  // namespace
}  // namespace mcf::multigrid_detail
