#include "datasets/generators.h"
#include "datasets/validate.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace mcf {
namespace {

constexpr double kPi = std::numbers::pi;

// Closed, consistently and outward oriented, genus g.
void expect_closed(const TriangleMesh& m, long long genus, const char* what) {
  const MeshReport r = validate_mesh(m, what);
  EXPECT_TRUE(r.closed()) << what << ": " << r.boundary_loops << " boundary loops";
  EXPECT_EQ(r.genus, genus) << what;
  EXPECT_EQ(r.connected_components, 1) << what;
  EXPECT_EQ(r.unreferenced_vertices, 0) << what;
  EXPECT_EQ(r.misoriented_edges, 0) << what;
  EXPECT_GT(test::signed_volume(m), 0) << what << ": faces point inward";
}

TEST(Generators, IcosphereCounts) {
  for (int level = 0; level <= 5; ++level) {
    const TriangleMesh m = make_icosphere(level);
    const long long p = 1ll << (2 * level);
    EXPECT_EQ(m.num_vertices(), 10 * p + 2) << level;
    EXPECT_EQ(m.num_faces(), 20 * p) << level;
    expect_closed(m, 0, "icosphere");
    EXPECT_NEAR(m.vertices.rowwise().norm().maxCoeff(), 1.0, 1e-12);
    EXPECT_NEAR(m.vertices.rowwise().norm().minCoeff(), 1.0, 1e-12);
  }
}

TEST(Generators, IcosphereAreaConvergesTo4Pi) {
  double previous_error = 1e9;
  for (int level = 1; level <= 6; ++level) {
    const double error = std::abs(surface_area(make_icosphere(level)) - 4 * kPi);
    EXPECT_LT(error, previous_error) << level;
    previous_error = error;
  }
  EXPECT_LT(previous_error / (4 * kPi), 1e-3);
  EXPECT_NEAR(surface_area(make_icosphere(4, 2.0)), 16 * kPi, 0.05 * 16 * kPi);
}

TEST(Generators, SphereByVertexCount) {
  for (long long target : {12ll, 100ll, 1000ll, 40000ll}) {
    const TriangleMesh m = make_sphere(target, 1.5);
    const long long k = std::llround(std::sqrt((target - 2) / 10.0));
    EXPECT_EQ(m.num_vertices(), 10 * k * k + 2) << target;
    EXPECT_NEAR(static_cast<double>(m.num_vertices()), static_cast<double>(target),
                0.2 * target + 12)
        << target;
    expect_closed(m, 0, "sphere");
    EXPECT_NEAR(m.vertices.rowwise().norm().minCoeff(), 1.5, 1e-12);
  }
  EXPECT_NEAR(surface_area(make_sphere(40000)), 4 * kPi, 1e-3 * 4 * kPi);
}

TEST(Generators, SphereIsQuasiUniform) {
  const TriangleMesh m = make_sphere(10000);
  double lo = 1e9, hi = 0;
  for (Eigen::Index f = 0; f < m.num_faces(); ++f) {
    const Eigen::Vector3d a = m.vertices.row(m.faces(f, 0)), b = m.vertices.row(m.faces(f, 1)),
                          c = m.vertices.row(m.faces(f, 2));
    const double area = 0.5 * (b - a).cross(c - a).norm();
    lo = std::min(lo, area);
    hi = std::max(hi, area);
  }
  EXPECT_LT(hi / lo, 2.5);
}

TEST(Generators, TorusGenusOne) {
  const TriangleMesh m = make_torus(1.0, 0.3, 48, 16);
  EXPECT_EQ(m.num_vertices(), 48 * 16);
  expect_closed(m, 1, "torus");
  EXPECT_NEAR(surface_area(make_torus(1.0, 0.3, 200, 80)), 4 * kPi * kPi * 0.3, 0.01);
  EXPECT_THROW(make_torus(0.3, 1.0, 8, 8), MeshError);
}

TEST(Generators, OpenCylinderHasTwoBoundaryLoops) {
  const TriangleMesh m = make_open_cylinder(0.5, 2.0, 32, 10);
  const MeshReport r = validate_mesh(m, "cylinder");
  EXPECT_EQ(r.boundary_loops, 2);
  EXPECT_EQ(r.genus, 0);
  EXPECT_EQ(r.misoriented_edges, 0);
  // Outward = away from the axis.
  const Eigen::Vector3d a = m.vertices.row(m.faces(0, 0)), b = m.vertices.row(m.faces(0, 1)),
                        c = m.vertices.row(m.faces(0, 2));
  Eigen::Vector3d centroid = (a + b + c) / 3;
  centroid.z() = 0;
  EXPECT_GT((b - a).cross(c - a).dot(centroid), 0);
  EXPECT_NEAR(r.area, 2 * kPi * 0.5 * 2.0, 0.02 * 2 * kPi);
}

TEST(Generators, CatenoidHasTwoBoundaryLoops) {
  const TriangleMesh m = make_catenoid(1.0, 1.0, 64, 24);
  const MeshReport r = validate_mesh(m, "catenoid");
  EXPECT_EQ(r.boundary_loops, 2);
  EXPECT_EQ(r.genus, 0);
  // Boundary circles have radius cosh(1).
  for (int v : boundary_vertices(m))
    EXPECT_NEAR(m.vertices.row(v).head<2>().norm(), std::cosh(1.0), 1e-12);
  // Exact area: π (2h + sinh(2h)) for waist 1.
  EXPECT_NEAR(r.area, kPi * (2 + std::sinh(2.0)), 0.01 * r.area);
}

TEST(Generators, SpiralHasBoundary) {
  const TriangleMesh m = make_cubical_spiral(3, 64, 4);
  const MeshReport r = validate_mesh(m, "spiral");
  EXPECT_FALSE(r.closed());
  EXPECT_EQ(r.boundary_loops, 1);  // a ribbon is a disk
  EXPECT_EQ(r.genus, 0);
  EXPECT_EQ(r.misoriented_edges, 0);
  // Square profile: |x| or |y| is 1 everywhere (the ribbon lies on a square prism).
  for (Eigen::Index v = 0; v < m.num_vertices(); ++v)
    EXPECT_NEAR(std::max(std::abs(m.vertices(v, 0)), std::abs(m.vertices(v, 1))), 1.0, 1e-12);
  // Area: 3 turns of an 8-long perimeter (slanted by the pitch), 0.6 high.
  EXPECT_NEAR(r.area, 3 * 8 * 0.6, 1e-9);
  EXPECT_NEAR(m.vertices.col(2).maxCoeff(), 3.6, 1e-12);
}

TEST(Generators, DumbbellIsClosedGenusZero) {
  const TriangleMesh m = make_dumbbell(64);
  expect_closed(m, 0, "dumbbell");
  // Thin neck: the narrowest ring near z = 0 is much thinner than the spheres.
  double neck = 1e9, widest = 0;
  for (Eigen::Index v = 0; v < m.num_vertices(); ++v) {
    const double rho = m.vertices.row(v).head<2>().norm();
    if (std::abs(m.vertices(v, 2)) < 0.2) neck = std::min(neck, rho);
    widest = std::max(widest, rho);
  }
  EXPECT_LT(neck, 0.3);
  EXPECT_NEAR(widest, 1.0, 0.01);
}

TEST(Generators, RoundedCylinderIsClosed) {
  const TriangleMesh m = make_rounded_cylinder(0.5, 2.0, 48);
  expect_closed(m, 0, "capsule");
  const double exact = 4 * kPi * 0.25 + 2 * kPi * 0.5 * 2.0;
  EXPECT_NEAR(surface_area(m), exact, 0.01 * exact);
}

// Smallest corner angle in degrees: no slivers that would spoil the finite elements (closed
// surfaces of revolution adapt the ring sizes, so their pole fans are not slivers either).
double min_angle_degrees(const TriangleMesh& m) {
  double lo = 180;
  for (Eigen::Index f = 0; f < m.num_faces(); ++f)
    for (int c = 0; c < 3; ++c) {
      const Eigen::Vector3d a = m.vertices.row(m.faces(f, c)),
                            b = m.vertices.row(m.faces(f, (c + 1) % 3)),
                            d = m.vertices.row(m.faces(f, (c + 2) % 3));
      const double cosine = std::clamp((b - a).normalized().dot((d - a).normalized()), -1.0, 1.0);
      lo = std::min(lo, std::acos(cosine) * 180 / kPi);
    }
  return lo;
}

TEST(Generators, NoSlivers) {
  EXPECT_GT(min_angle_degrees(make_sphere(20000)), 50);
  EXPECT_GT(min_angle_degrees(make_icosphere(4)), 50);
  EXPECT_GT(min_angle_degrees(make_torus()), 30);
  EXPECT_GT(min_angle_degrees(make_cubical_spiral()), 30);
  EXPECT_GT(min_angle_degrees(make_open_cylinder()), 40);
  EXPECT_GT(min_angle_degrees(make_catenoid()), 35);
  EXPECT_GT(min_angle_degrees(make_dumbbell(64)), 25);
  EXPECT_GT(min_angle_degrees(make_rounded_cylinder(0.5, 2.0, 64)), 25);
}

TEST(Generators, SpiralFacesPointAwayFromTheAxis) {
  const TriangleMesh m = make_cubical_spiral(2, 32, 2);
  for (Eigen::Index f = 0; f < m.num_faces(); ++f) {
    const Eigen::Vector3d a = m.vertices.row(m.faces(f, 0)), b = m.vertices.row(m.faces(f, 1)),
                          c = m.vertices.row(m.faces(f, 2));
    Eigen::Vector3d centroid = (a + b + c) / 3;
    centroid.z() = 0;
    ASSERT_GT((b - a).cross(c - a).dot(centroid), 0) << f;
  }
}

}  // namespace
}  // namespace mcf
