// The band's normal-gradient matrix S_IJ = ∫ (n·∇B_I)(n·∇B_J) dV (bases/normal_gradient.h).
// References: the unit cell's integrals in closed form (products of 1-D integrals), and linear
// functions on planar surfaces, whose S-energy is known exactly.
#include "bases/normal_gradient.h"
#include "bases/octree_basis.h"
#include "bases/tracked_octree_basis.h"
#include "test_meshes.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>

namespace {

using namespace mcf;

// ∫_0^1 of the product of two 1-D hats' values (v) or derivatives (d), corner offsets o1, o2.
double hat_integral(bool d1, int o1, bool d2, int o2) {
  if (d1 && d2) return (o1 == o2) ? 1.0 : -1.0;              // (±1)(±1)
  if (d1 != d2) return ((d1 ? o1 : o2) ? 1.0 : -1.0) * 0.5;  // ±∫ t or ±∫ (1-t)
  return o1 == o2 ? 1.0 / 3.0 : 1.0 / 6.0;                   // ∫ t², ∫ t(1-t)
}

TEST(NormalGradient, UnitTablesAreTheClosedFormIntegrals) {
  const auto& T = unit_gradient_tables();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int a = 0; a < 8; ++a)
        for (int b = 0; b < 8; ++b) {
          const auto oa = corner_offset(a), ob = corner_offset(b);
          double expected = 1.0;
          for (int axis = 0; axis < 3; ++axis)
            expected *=
                hat_integral(axis == i, oa[std::size_t(axis)], axis == j, ob[std::size_t(axis)]);
          EXPECT_NEAR(T[std::size_t(3 * i + j)][std::size_t(8 * a + b)], expected, 1e-14)
              << "i " << i << " j " << j << " a " << a << " b " << b;
        }
}

// A square grid of triangles on the plane through p with unit normal n (two tangents u, v).
TriangleMesh plane_patch(const Eigen::Vector3d& p, const Eigen::Vector3d& n, double size, int k) {
  Eigen::Vector3d u = n.unitOrthogonal(), v = n.cross(u);
  TriangleMesh m;
  m.vertices.resize((k + 1) * (k + 1), 3);
  for (int j = 0; j <= k; ++j)
    for (int i = 0; i <= k; ++i)
      m.vertices.row(j * (k + 1) + i) =
          (p + size * ((i / double(k) - 0.5) * u + (j / double(k) - 0.5) * v)).transpose();
  m.faces.resize(2 * k * k, 3);
  int f = 0;
  for (int j = 0; j < k; ++j)
    for (int i = 0; i < k; ++i) {
      const int a = j * (k + 1) + i, b = a + 1, c = a + k + 1, d = c + 1;
      m.faces.row(f++) << a, b, d;
      m.faces.row(f++) << a, d, c;
    }
  return m;
}

double band_volume(const RebuiltOctreeBasis& b) {
  const double h = b.octree().cube.cell_size();
  return double(b.octree().finest().cells.size()) * h * h * h;
}

TEST(NormalGradient, LinearFunctionsOnATiltedPlane) {
  const Eigen::Vector3d n = Eigen::Vector3d(1.0, 2.0, 2.0).normalized();
  const TriangleMesh mesh = plane_patch(Eigen::Vector3d(0.5, 0.5, 0.5), n, 0.6, 24);
  OctreeOptions o;
  o.depth = 5;
  o.cube = OctreeCube::unit;
  o.normal_gradient = true;
  const RebuiltOctreeBasis basis(mesh, o);
  const SparseMatrix S = basis.normal_gradient();
  ASSERT_EQ(S.rows(), basis.dimension());
  EXPECT_EQ(S.nonZeros(), SparseMatrix(basis.mass()).nonZeros());  // the pattern of M and K
  const Coefficients c = basis.initial_coefficients();  // the grid vertices: x = Σ c_I B_I
  // u = n·x: n·∇u = 1 everywhere, so uᵀ S u is the band's volume.
  const Eigen::VectorXd along = c * n;
  EXPECT_NEAR(along.dot(S * along) / band_volume(basis), 1.0, 1e-12);
  // u = t·x with t ⟂ n is constant along n: S u = 0.
  const Eigen::VectorXd across = c * n.unitOrthogonal();
  EXPECT_LT((S * across).cwiseAbs().maxCoeff(), 1e-14);
  // Constants too.
  EXPECT_LT((S * Eigen::VectorXd::Ones(S.rows())).cwiseAbs().maxCoeff(), 1e-14);
  // Symmetric positive semi-definite.
  EXPECT_EQ((S - SparseMatrix(S.transpose())).norm(), 0.0);
}

TEST(NormalGradient, BilinearFunctionsOnAnAxisPlaneAreFree) {
  // On z = const every cell's normal is e_z: any function of (x, y) alone, e.g. the trilinear
  // interpolant of x y, has zero S-energy; z has energy equal to the band's volume.
  const TriangleMesh mesh =
      plane_patch(Eigen::Vector3d(0.5, 0.5, 0.51), Eigen::Vector3d::UnitZ(), 0.7, 16);
  OctreeOptions o;
  o.depth = 5;
  o.cube = OctreeCube::unit;
  o.normal_gradient = true;
  const RebuiltOctreeBasis basis(mesh, o);
  const SparseMatrix S = basis.normal_gradient();
  const Coefficients c = basis.initial_coefficients();
  const Eigen::VectorXd xy = c.col(0).cwiseProduct(c.col(1));
  EXPECT_LT((S * xy).cwiseAbs().maxCoeff(), 1e-14);
  const Eigen::VectorXd z = c.col(2);
  EXPECT_NEAR(z.dot(S * z) / band_volume(basis), 1.0, 1e-12);
}

TEST(NormalGradient, NearNullModeOfTheSphereGetsEnergyAndTrackedEqualsRebuilt) {
  const TriangleMesh mesh = test_icosphere(4, 1.0);
  OctreeOptions o;
  o.depth = 5;
  o.normal_gradient = true;
  const RebuiltOctreeBasis rebuilt(mesh, o);
  const TrackedOctreeBasis tracked(mesh, o);
  const SparseMatrix S = rebuilt.normal_gradient();
  EXPECT_EQ((S - SparseMatrix(tracked.normal_gradient())).norm(), 0.0);
  // The interpolant of |x|² - 1 nearly vanishes on the sphere (its M-energy is tiny against its
  // coefficients'), while its gradient 2x points along the normal: S sees it fully.
  const Coefficients c = rebuilt.initial_coefficients();
  const Eigen::VectorXd phi = c.rowwise().squaredNorm().array() - 1.0;
  const SparseMatrix M = rebuilt.mass();
  const Eigen::VectorXd dM = M.diagonal(), dS = S.diagonal();
  const double trace_part = phi.dot(M * phi) / phi.dot(dM.cwiseProduct(phi));
  const double normal_part = phi.dot(S * phi) / phi.dot(dS.cwiseProduct(phi));
  EXPECT_LT(trace_part, 0.05);
  EXPECT_GT(normal_part, 0.5);
  // Without the option there is none.
  OctreeOptions plain = o;
  plain.normal_gradient = false;
  EXPECT_EQ(RebuiltOctreeBasis(mesh, plain).normal_gradient().rows(), 0);
}

TEST(NormalGradient, IndependentOfTheThreadCount) {
  const TriangleMesh mesh = test_icosphere(4, 1.0);
  OctreeOptions o;
  o.depth = 6;
  o.normal_gradient = true;
  SparseMatrix S1, S2;
  {
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    S1 = RebuiltOctreeBasis(mesh, o).normal_gradient();
  }
  {
    tbb::global_control two(tbb::global_control::max_allowed_parallelism, 2);
    S2 = RebuiltOctreeBasis(mesh, o).normal_gradient();
  }
  EXPECT_EQ((S1 - S2).norm(), 0.0);
}

}  // namespace
