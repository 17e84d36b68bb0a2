// Metrics of harness/metrics.h against cases with known answers.

#include "datasets/generators.h"
#include "harness/metrics.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <sstream>
#include <string>

namespace mcf {
namespace {

/// Unit square [x0, x0+w] × [0, 1] at height z, split into 2·n·n triangles (normal +z).
/// warp > 1 crowds the columns towards x0 (x = x0 + w (i/n)^warp): triangles of very unequal area.
TriangleMesh make_patch(int n, double x0 = 0, double w = 1, double z = 0, double warp = 1) {
  TriangleMesh m;
  m.vertices.resize((n + 1) * (n + 1), 3);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      m.vertices.row(j * (n + 1) + i) << x0 + w * std::pow(double(i) / n, warp), double(j) / n, z;
  m.faces.resize(2 * n * n, 3);
  int f = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int v = j * (n + 1) + i;
      m.faces.row(f++) << v, v + 1, v + n + 2;
      m.faces.row(f++) << v, v + n + 2, v + n + 1;
    }
  return m;
}

/// Largest sagitta of a sphere mesh whose vertices lie on the sphere of radius r: r minus the
/// distance from the centre to the nearest face plane (r² − circumradius²)^½.
double max_sagitta(const TriangleMesh& m, double r) {
  double worst = 0;
  for (Eigen::Index t = 0; t < m.num_faces(); ++t) {
    const Eigen::Vector3d a = m.vertices.row(m.faces(t, 0)), b = m.vertices.row(m.faces(t, 1)),
                          c = m.vertices.row(m.faces(t, 2));
    const double la = (b - c).norm(), lb = (a - c).norm(), lc = (a - b).norm();
    const double area = 0.5 * (b - a).cross(c - a).norm();
    const double circumradius = la * lb * lc / (4 * area);
    worst = std::max(worst, r - std::sqrt(r * r - circumradius * circumradius));
  }
  return worst;
}

TEST(MeshDistance, ConcentricIcospheresDifferByTheGapUpToTheSagitta) {
  const TriangleMesh inner = make_icosphere(5, 1.0), outer = make_icosphere(5, 1.1);
  // Inner surface lies between the balls of radius 1−s₁ and 1, the outer one between 1.1−s₂ and
  // 1.1 (convex polyhedra inscribed in their spheres), so every distance is in [0.1−s₂, 0.1+s₁].
  const double s1 = max_sagitta(inner, 1.0), s2 = max_sagitta(outer, 1.1);
  ASSERT_LT(s1, 2e-3);
  const MeshDistance d = mesh_distance(inner, outer, 20000, 7);
  EXPECT_EQ(d.samples, 20000);
  for (const double x :
       {d.rms_forward, d.max_forward, d.rms_backward, d.max_backward, d.rms, d.max}) {
    EXPECT_GE(x, 0.1 - s2 - 1e-12);
    EXPECT_LE(x, 0.1 + s1 + 1e-12);
  }
  EXPECT_GT(d.max, d.rms);
}

TEST(MeshDistance, PatchTranslatedAlongItsNormalIsAtDistanceTEverywhere) {
  const double t = 0.0375;
  const TriangleMesh a = make_patch(12), b = make_patch(7, 0, 1, t);  // different triangulations
  const MeshDistance d = mesh_distance(a, b, 5000, 3);
  for (const double x :
       {d.rms_forward, d.max_forward, d.rms_backward, d.max_backward, d.rms, d.max})
    EXPECT_NEAR(x, t, 1e-12);
}

TEST(MeshDistance, SubPatchIsOneSided) {
  // B = left half of A: every sample of B lies on A (backward 0), samples of A at x > 1/2 are
  // x − 1/2 from B: forward max → 1/2, forward RMS² = ∫_{1/2}^1 (x−1/2)² dx = 1/24.
  const TriangleMesh a = make_patch(10), b = make_patch(6, 0, 0.5);
  const MeshDistance d = mesh_distance(a, b, 200000, 11);
  EXPECT_LT(d.max_backward, 1e-12);
  EXPECT_LT(d.rms_backward, 1e-12);
  EXPECT_NEAR(d.max_forward, 0.5, 2e-3);
  EXPECT_NEAR(d.rms_forward, std::sqrt(1.0 / 24), 0.01 * std::sqrt(1.0 / 24));
  EXPECT_DOUBLE_EQ(d.max, d.max_forward);
  EXPECT_NEAR(d.rms, std::sqrt(1.0 / 48), 0.01 * std::sqrt(1.0 / 48));
}

TEST(MeshDistance, SamplingIsUniformByAreaNotByTriangle) {
  // Same case as SubPatchIsOneSided, but A's triangles crowd at x = 0 (areas differ 100-fold):
  // sampling per triangle instead of per area would pull the forward RMS far below √(1/24).
  const TriangleMesh a = make_patch(20, 0, 1, 0, 3.0), b = make_patch(4, 0, 0.5);
  const MeshDistance d = mesh_distance(a, b, 200000, 13);
  EXPECT_NEAR(d.rms_forward, std::sqrt(1.0 / 24), 0.01 * std::sqrt(1.0 / 24));
  EXPECT_LT(d.rms_backward, 1e-12);
}

TEST(MeshDistance, InPlaneShiftGivesTheIntegralOfTheOverhang) {
  // B = A shifted by s along x: the overhang strip of width s is (s − x) away, both ways alike.
  const double s = 0.3, expect = std::sqrt(s * s * s / 3);
  const MeshDistance d = mesh_distance(make_patch(9), make_patch(9, s), 200000, 5);
  EXPECT_NEAR(d.rms_forward, expect, 0.01 * expect);
  EXPECT_NEAR(d.rms_backward, expect, 0.01 * expect);
  EXPECT_NEAR(d.max_forward, s, 2e-3);
  EXPECT_LE(d.max, s + 1e-12);
}

TEST(MeshDistance, IdenticalMeshesAreAtZero) {
  const TriangleMesh m = make_torus(1.0, 0.3, 40, 16);
  const MeshDistance d = mesh_distance(m, m, 10000, 1);
  EXPECT_LT(d.max, 1e-12);
}

TEST(MeshDistance, DeterministicForASeedWhateverTheThreadCount) {
  const TriangleMesh a = make_torus(1.0, 0.3, 48, 16), b = make_icosphere(3, 1.2);
  const MeshDistance many = mesh_distance(a, b, 30000, 42);
  MeshDistance one;
  {
    tbb::global_control serial(tbb::global_control::max_allowed_parallelism, 1);
    one = mesh_distance(a, b, 30000, 42);
  }
  EXPECT_EQ(many.rms, one.rms);  // bitwise: ordered reduction
  EXPECT_EQ(many.max, one.max);
  EXPECT_EQ(many.rms_forward, one.rms_forward);
  const MeshDistance other_seed = mesh_distance(a, b, 30000, 43);
  EXPECT_NE(many.rms_forward, other_seed.rms_forward);
  EXPECT_NEAR(many.rms_forward, other_seed.rms_forward, 0.02 * many.rms_forward);
}

TEST(MeshDistance, RejectsEmptyMeshesAndNonPositiveSamples) {
  const TriangleMesh m = make_icosphere(1);
  EXPECT_THROW(mesh_distance(m, TriangleMesh{}, 10), std::invalid_argument);
  EXPECT_THROW(mesh_distance(m, m, 0), std::invalid_argument);
}

Eigen::Matrix3d rotation() {
  return (Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()) *
          Eigen::AngleAxisd(-1.1, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

TEST(QuasiConformal, SimilarityIsOne) {
  const TriangleMesh m = make_torus(1.0, 0.3, 32, 12);
  const Positions moved =
      ((m.vertices * rotation().transpose()) * 2.5).rowwise() + Eigen::RowVector3d(1, -2, 0.5);
  EXPECT_NEAR(quasi_conformal_error(m, moved), 1.0, 1e-12);
  EXPECT_NEAR(quasi_conformal_error(m, m.vertices), 1.0, 1e-14);
}

TEST(QuasiConformal, StretchOfAPlanarMeshIsTheStretchRatio) {
  // diag(2,1,1) on a mesh in the xy-plane: in every triangle's frame the map has σ = 2 and 1.
  TriangleMesh m = make_patch(8);
  // Irregular triangles, so the frames are not aligned with the stretch axis.
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> jitter(-0.03, 0.03);
  for (Eigen::Index v = 0; v < m.num_vertices(); ++v)
    m.vertices.row(v) += Eigen::RowVector3d(jitter(rng), jitter(rng), 0);
  Positions stretched = m.vertices;
  stretched.col(0) *= 2;
  EXPECT_NEAR(quasi_conformal_error(m, stretched), 2.0, 1e-12);
  // Then a similarity on top changes nothing.
  const Positions moved = (stretched * rotation().transpose()) * 0.3;
  EXPECT_NEAR(quasi_conformal_error(m, moved), 2.0, 1e-12);
}

TEST(QuasiConformal, DegenerateCurrentTrianglesAreSkipped) {
  TriangleMesh m = make_patch(2);
  Positions collapsed = m.vertices;
  collapsed.col(1).setZero();  // every triangle flat: nothing left to average
  EXPECT_TRUE(std::isnan(quasi_conformal_error(m, collapsed)));
  Positions one = m.vertices;
  one.row(0) = one.row(1);  // one triangle at vertex 0 collapses, the other is sheared
  const double q = quasi_conformal_error(m, one);
  EXPECT_TRUE(std::isfinite(q));
  EXPECT_GT(q, 1.0);
  EXPECT_THROW(quasi_conformal_error(m, Positions(3, 3)), std::invalid_argument);
}

/// Continuous counterpart of sphericity for the ellipsoid of revolution x²/a² + y² + z² = 1
/// (centre 0 by symmetry): σ/μ of |p| under the area measure, by the midpoint rule in u,
/// with p = (a cos u, sin u cos φ, sin u sin φ), dA = 2π sin u √(a² sin²u + cos²u) du.
double ellipsoid_sphericity(double a) {
  const int n = 200000;
  double area = 0, m1 = 0, m2 = 0;
  for (int i = 0; i < n; ++i) {
    const double u = (i + 0.5) * std::numbers::pi / n;
    const double s = std::sin(u), c = std::cos(u);
    const double da = s * std::sqrt(a * a * s * s + c * c);
    const double d = std::sqrt(a * a * c * c + s * s);
    area += da;
    m1 += da * d;
    m2 += da * d * d;
  }
  const double mean = m1 / area;
  return std::sqrt(m2 / area - mean * mean) / mean;
}

TEST(Sphericity, SphereIsZeroEllipsoidMatchesTheIntegral) {
  const TriangleMesh sphere = make_icosphere(5, 2.0);
  EXPECT_LT(sphericity(sphere.vertices, sphere.faces), 1e-12);
  const TriangleMesh shifted{sphere.vertices.rowwise() + Eigen::RowVector3d(5, -1, 2),
                             sphere.faces};
  EXPECT_LT(sphericity(shifted.vertices, shifted.faces), 1e-12);  // centre is found, not assumed

  double previous = 0;
  for (const double a : {1.1, 1.5, 2.0}) {
    Positions v = sphere.vertices / 2.0;
    v.col(0) *= a;
    const double s = sphericity(v, sphere.faces), expect = ellipsoid_sphericity(a);
    EXPECT_NEAR(s, expect, 0.01 * expect) << "a = " << a;
    EXPECT_GT(s, previous);
    previous = s;
  }
}

}  // namespace
}  // namespace mcf
