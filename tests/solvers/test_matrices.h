#pragma once
// SPD test systems shaped like the finite-element systems the flows produce:
// (mass-like diagonal) + (Laplacian-like stiffness), three right-hand sides.

#include "solvers/linear_solver.h"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <random>
#include <vector>

namespace mcf::test {

/// 3D 7-point Laplacian on an nx*ny*nz grid plus a random diagonal in [m, 2m].
inline SparseMatrix laplacian3d(int nx, int ny, int nz, double m = 0.1, unsigned seed = 1,
                                double stiffness = 1.0) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const int n = nx * ny * nz;
  auto id = [&](int i, int j, int k) { return (k * ny + j) * nx + i; };
  std::vector<Eigen::Triplet<double>> t;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const int a = id(i, j, k);
        double diag = m * (1.0 + u(rng));
        const int nb[6][3] = {{i - 1, j, k}, {i + 1, j, k}, {i, j - 1, k},
                              {i, j + 1, k}, {i, j, k - 1}, {i, j, k + 1}};
        for (const auto& q : nb) {
          if (q[0] < 0 || q[0] >= nx || q[1] < 0 || q[1] >= ny || q[2] < 0 || q[2] >= nz) continue;
          t.emplace_back(a, id(q[0], q[1], q[2]), -stiffness);
          diag += stiffness;
        }
        t.emplace_back(a, a, diag);
      }
  SparseMatrix A(n, n);
  A.setFromTriplets(t.begin(), t.end());
  A.makeCompressed();
  return A;
}

/// Random weighted graph Laplacian (each node linked to `degree` random others) + diagonal
/// in [m, 2m]; symmetric by construction.
inline SparseMatrix graph_laplacian(int n, int degree = 4, double m = 0.05, unsigned seed = 2) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::uniform_int_distribution<int> node(0, n - 1);
  std::vector<Eigen::Triplet<double>> t;
  Eigen::VectorXd diag(n);
  for (int i = 0; i < n; ++i) diag[i] = m * (1.0 + u(rng));
  for (int i = 0; i < n; ++i)
    for (int d = 0; d < degree; ++d) {
      const int j = node(rng);
      if (j == i) continue;
      const double w = 0.1 + u(rng);
      t.emplace_back(i, j, -w);
      t.emplace_back(j, i, -w);
      diag[i] += w;
      diag[j] += w;
    }
  for (int i = 0; i < n; ++i) t.emplace_back(i, i, diag[i]);
  SparseMatrix A(n, n);
  A.setFromTriplets(t.begin(), t.end());  // duplicates summed: still symmetric
  A.makeCompressed();
  return A;
}

/// P A Pᵀ for the permutation i -> (i * stride) mod n (stride coprime to n): the same size and
/// number of nonzeros as A, another pattern (for the solvers' pattern comparison), compressed.
inline SparseMatrix symmetric_permutation(const SparseMatrix& A, int stride) {
  Eigen::VectorXi order(A.rows());
  for (Eigen::Index i = 0; i < order.size(); ++i) order[i] = int((i * stride) % order.size());
  const Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> perm(order);
  SparseMatrix P;
  P = A.twistedBy(perm);
  P.makeCompressed();
  return P;
}

inline Eigen::MatrixXd random_rhs(Eigen::Index n, Eigen::Index k = 3, unsigned seed = 3) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  Eigen::MatrixXd B(n, k);
  for (Eigen::Index c = 0; c < k; ++c)
    for (Eigen::Index i = 0; i < n; ++i) B(i, c) = g(rng);
  return B;
}

inline double relative_difference(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y) {
  return (X - Y).norm() / Y.norm();
}

/// max_c ||b_c - A x_c|| / ||b_c||, computed independently of the solvers.
inline double relative_residual(const SparseMatrix& A, const Eigen::MatrixXd& B,
                                const Eigen::MatrixXd& X) {
  const Eigen::MatrixXd R = B - A * X;
  double worst = 0.0;
  for (Eigen::Index c = 0; c < B.cols(); ++c)
    worst = std::max(worst, R.col(c).norm() / B.col(c).norm());
  return worst;
}

}  // namespace mcf::test
