// Hat basis against independent references: per-triangle gradients of the barycentric
// functions (not the cotangent formula), exact quadrature of the P1 mass, and the sphere's
// Dirichlet energy Σ_coords ∫|∇x|² = 2·area.

#include "bases/hat_basis.h"
#include "datasets/generators.h"
#include "datasets/subdivide.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <Eigen/Dense>

#include <random>

namespace mcf {
namespace {

TriangleMesh random_triangle_fan(unsigned seed) {
  // A disk-like fan around vertex 0 with random positions: not symmetric, not planar.
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  const int n = 7;
  TriangleMesh m;
  m.vertices.resize(n + 1, 3);
  m.vertices.row(0) << u(rng), u(rng), 1.0 + u(rng);
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    m.vertices.row(i + 1) << std::cos(a) + u(rng), std::sin(a) + u(rng), u(rng);
  }
  m.faces.resize(n, 3);
  for (int i = 0; i < n; ++i) m.faces.row(i) << 0, 1 + i, 1 + (i + 1) % n;
  return m;
}

// Reference assembly from explicit gradients: ∇φ_i = (n × e_i) / (2A), e_i the opposite edge.
Eigen::MatrixXd reference_stiffness(const TriangleMesh& m) {
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(m.num_vertices(), m.num_vertices());
  for (Eigen::Index f = 0; f < m.num_faces(); ++f) {
    Eigen::Vector3d p[3];
    for (int a = 0; a < 3; ++a) p[a] = m.vertices.row(m.faces(f, a)).transpose();
    const Eigen::Vector3d n2 = (p[1] - p[0]).cross(p[2] - p[0]);
    const double A = 0.5 * n2.norm();
    const Eigen::Vector3d n = n2.normalized();
    Eigen::Vector3d g[3];
    for (int a = 0; a < 3; ++a) g[a] = n.cross(p[(a + 2) % 3] - p[(a + 1) % 3]) / (2 * A);
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) K(m.faces(f, a), m.faces(f, b)) += A * g[a].dot(g[b]);
  }
  return K;
}

// Mass by the degree-2 edge-midpoint rule, exact for the quadratic φ_i φ_j.
Eigen::MatrixXd reference_mass(const TriangleMesh& m) {
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(m.num_vertices(), m.num_vertices());
  const double bary[3][3] = {{0.5, 0.5, 0}, {0, 0.5, 0.5}, {0.5, 0, 0.5}};
  for (Eigen::Index f = 0; f < m.num_faces(); ++f) {
    const Eigen::Vector3d a = m.vertices.row(m.faces(f, 0)), b = m.vertices.row(m.faces(f, 1)),
                          c = m.vertices.row(m.faces(f, 2));
    const double A = 0.5 * (b - a).cross(c - a).norm();
    for (const auto& q : bary)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) M(m.faces(f, i), m.faces(f, j)) += A / 3.0 * q[i] * q[j];
  }
  return M;
}

TEST(HatBasis, MatchesIndependentAssembly) {
  const TriangleMesh m = random_triangle_fan(7);
  HatBasis basis(m);
  const Eigen::MatrixXd K = Eigen::MatrixXd(basis.stiffness());
  const Eigen::MatrixXd M = Eigen::MatrixXd(basis.mass());
  EXPECT_LT((K - reference_stiffness(m)).norm(), 1e-12 * K.norm());
  EXPECT_LT((M - reference_mass(m)).norm(), 1e-12 * M.norm());
}

TEST(HatBasis, ConstantsInKernelMassSumsToArea) {
  const TriangleMesh m = make_icosphere(3);
  for (MassKind kind : {MassKind::consistent, MassKind::lumped}) {
    HatBasis basis(m, kind);
    const Eigen::VectorXd ones = Eigen::VectorXd::Ones(m.num_vertices());
    EXPECT_LT((basis.stiffness() * ones).cwiseAbs().maxCoeff(), 1e-12);
    double area = 0;
    for (Eigen::Index f = 0; f < m.num_faces(); ++f) {
      const Eigen::Vector3d a = m.vertices.row(m.faces(f, 0)), b = m.vertices.row(m.faces(f, 1)),
                            c = m.vertices.row(m.faces(f, 2));
      area += 0.5 * (b - a).cross(c - a).norm();
    }
    EXPECT_NEAR(ones.dot(basis.mass() * ones), area, 1e-12 * area);
    const SparseMatrix Kt = basis.stiffness().transpose();
    EXPECT_LT((basis.stiffness() - Kt).norm(), 1e-14 * basis.stiffness().norm());
  }
}

TEST(HatBasis, LumpedMassIsTheRowSumsOfTheConsistentOne) {
  // Lumped: M_ii = Σ_{f ∋ i} A_f / 3, the row sums of the consistent mass, and nothing off the
  // diagonal; the stiffness does not depend on the mass kind.
  const TriangleMesh m = random_triangle_fan(7);
  HatBasis lumped(m, MassKind::lumped), consistent(m, MassKind::consistent);
  const Eigen::MatrixXd M = Eigen::MatrixXd(lumped.mass());
  const Eigen::VectorXd row_sums = reference_mass(m).rowwise().sum();
  EXPECT_LT((Eigen::MatrixXd(M.diagonal().asDiagonal()) - M).norm(), 1e-15 * M.norm());
  EXPECT_LT((M.diagonal() - row_sums).norm(), 1e-12 * row_sums.norm());
  EXPECT_EQ((Eigen::MatrixXd(lumped.stiffness()) - Eigen::MatrixXd(consistent.stiffness())).norm(),
            0.0);
}

TEST(HatBasis, SphereDirichletEnergyConverges) {
  // Σ_coords ∫|∇_S x|² = ∫ 2 dA = 8π on the unit sphere; the error falls as the mesh refines.
  double previous = 1e9;
  for (int level = 2; level <= 5; ++level) {
    const TriangleMesh m = make_icosphere(level);
    HatBasis basis(m);
    const Coefficients x = basis.initial_coefficients();
    const double energy = (x.transpose() * (basis.stiffness() * x)).trace();
    const double error = std::abs(energy - 8 * M_PI);
    EXPECT_LT(error, 0.5 * previous) << "level " << level;
    previous = error;
  }
  EXPECT_LT(previous, 1e-2 * 8 * M_PI);
}

TEST(HatBasis, UpdateFollowsTheEmbedding) {
  // Scaling the embedding by s scales the mass by s² and leaves the (2-D, scale-free) stiffness.
  const TriangleMesh m = make_icosphere(2);
  HatBasis basis(m);
  const SparseMatrix M0 = basis.mass(), K0 = basis.stiffness();
  basis.update(3.0 * basis.initial_coefficients(), true, true);
  EXPECT_LT((basis.mass() - 9.0 * M0).norm(), 1e-12 * 9 * M0.norm());
  EXPECT_LT((basis.stiffness() - K0).norm(), 1e-12 * K0.norm());
}

// The update gathers per-face areas and corner weights per nonzero: after a random move, updating
// one operator matches the reference assembly of the moved mesh and leaves the other as it was
// (on a closed mesh, where every diagonal gathers its vertex's whole ring).
TEST(HatBasis, PartialUpdatesMatchTheReferenceAssembly) {
  TriangleMesh m = make_icosphere(2);
  HatBasis basis(m);
  TriangleMesh moved = m;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  for (Eigen::Index i = 0; i < moved.vertices.rows(); ++i)
    for (int c = 0; c < 3; ++c) moved.vertices(i, c) += u(rng);
  const Eigen::MatrixXd M0 = reference_mass(m), K0 = reference_stiffness(m);
  const Eigen::MatrixXd M1 = reference_mass(moved), K1 = reference_stiffness(moved);
  ASSERT_GT((M1 - M0).norm(), 1e-3 * M0.norm());
  ASSERT_GT((K1 - K0).norm(), 1e-3 * K0.norm());
  basis.update(moved.vertices, true, false);
  EXPECT_LT((Eigen::MatrixXd(basis.mass()) - M1).norm(), 1e-12 * M1.norm());
  EXPECT_LT((Eigen::MatrixXd(basis.stiffness()) - K0).norm(), 1e-12 * K0.norm());
  basis.update(moved.vertices, false, true);
  EXPECT_LT((Eigen::MatrixXd(basis.stiffness()) - K1).norm(), 1e-12 * K1.norm());
}

// The update's per-face pass is vectorized over a block of faces with a scalar remainder that may
// round differently; the blocks' bounds depend on the faces and the grain only, so the mass and
// stiffness are bitwise the same for one and for two threads and on every repetition (with TBB's
// auto partitioner the split moved with the threads' timing: a cMCF flow differed from run to
// run in its last bits).
TEST(HatBasis, UpdatesAreBitwiseTheSameForAnyThreadsAndRun) {
  TriangleMesh m = make_icosphere(6);  // 81920 faces: many blocks of the update's grain
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.01, 0.01);
  for (Eigen::Index i = 0; i < m.vertices.rows(); ++i)
    for (int c = 0; c < 3; ++c) m.vertices(i, c) *= 1.0 + u(rng);
  const auto assemble = [&](int threads, bool stiffness) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
    HatBasis basis(make_icosphere(6));
    basis.update(m.vertices, true, stiffness);
    const SparseMatrix M = basis.mass(), K = basis.stiffness();
    return std::make_pair(std::vector<double>(M.valuePtr(), M.valuePtr() + M.nonZeros()),
                          std::vector<double>(K.valuePtr(), K.valuePtr() + K.nonZeros()));
  };
  for (const bool stiffness : {false, true}) {
    const auto one = assemble(1, stiffness);
    for (int run = 0; run < 4; ++run) EXPECT_EQ(assemble(2, stiffness), one) << run;
  }
}

// Mass and stiffness are values on the basis's one pattern: both views show the same index
// arrays, and an update rewrites the values in place (the views' arrays do not move).
TEST(HatBasis, MassAndStiffnessShareOnePattern) {
  const TriangleMesh mesh = random_triangle_fan(5);
  HatBasis basis(mesh);
  const SparseView M = basis.mass(), K = basis.stiffness();
  EXPECT_EQ(M.outerIndexPtr(), K.outerIndexPtr());
  EXPECT_EQ(M.innerIndexPtr(), K.innerIndexPtr());
  EXPECT_NE(M.valuePtr(), K.valuePtr());
  EXPECT_EQ(M.nonZeros(),
            8 + 2 * 14);  // the diagonal and both directions of 7 spokes and 7 rim edges
  const SparseMatrix M0 = M;
  basis.update(2.0 * mesh.vertices, true, true);
  EXPECT_EQ(basis.mass().valuePtr(), M.valuePtr());
  EXPECT_LT((SparseMatrix(basis.mass()) - 4.0 * M0).norm(), 1e-12 * M0.norm());  // areas scale by 4
}

TEST(HatBasis, RenumberedForAHierarchyItAssemblesTheSameMatrices) {
  // With a hierarchy the functions are numbered in Cuthill-McKee order and the assembly reads the
  // faces sorted by their first function; the matrices are the mesh-order basis's, renumbered,
  // up to the order in which a nonzero's faces are added. An ellipsoid split once: its midpoints
  // are numbered after the corners, so both orders differ from the mesh's.
  TriangleMesh m = subdivide_midpoint(make_icosphere(4));
  m.vertices.col(0) *= 1.5;
  HatBasis plain(m);
  HatBasis ordered(m, MassKind::consistent, SurfaceHierarchyOptions{});
  const Eigen::Index n = m.num_vertices();
  Coefficients index = Coefficients::Zero(n, 3);
  for (Eigen::Index k = 0; k < n; ++k) index(k, 0) = double(k);
  const Positions function_of = ordered.evaluate_vertices(index);  // vertex v is function (v, 0)
  std::vector<int> k_of(static_cast<std::size_t>(n));
  bool renumbered = false;
  for (Eigen::Index v = 0; v < n; ++v) {
    k_of[std::size_t(v)] = int(function_of(v, 0));
    renumbered = renumbered || k_of[std::size_t(v)] != int(v);
  }
  ASSERT_TRUE(renumbered);
  const auto compare = [&](const char* when) {
    for (const bool stiffness : {false, true}) {
      const SparseMatrix A =
          stiffness ? SparseMatrix(plain.stiffness()) : SparseMatrix(plain.mass());
      const SparseMatrix B =
          stiffness ? SparseMatrix(ordered.stiffness()) : SparseMatrix(ordered.mass());
      ASSERT_EQ(A.nonZeros(), B.nonZeros());
      const double scale = A.coeffs().cwiseAbs().maxCoeff();
      double worst = 0;
      for (int j = 0; j < A.outerSize(); ++j)
        for (SparseMatrix::InnerIterator it(A, j); it; ++it)
          worst = std::max(worst, std::abs(it.value() - B.coeff(k_of[std::size_t(it.row())],
                                                                k_of[std::size_t(j)])));
      EXPECT_LE(worst, 1e-13 * scale) << when << (stiffness ? " stiffness" : " mass");
    }
  };
  compare("initial");
  // A random move, updated in both numberings.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.02, 0.02);
  Positions X = m.vertices;
  for (Eigen::Index v = 0; v < n; ++v)
    for (int c = 0; c < 3; ++c) X(v, c) += u(rng);
  Coefficients Y(n, 3);
  for (Eigen::Index v = 0; v < n; ++v) Y.row(k_of[std::size_t(v)]) = X.row(v);
  plain.update(X, true, true);
  ordered.update(Y, true, true);
  compare("moved");
}

}  // namespace
}  // namespace mcf
