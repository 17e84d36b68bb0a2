// Closest points of datasets/bvh.h: Ericson's point-to-triangle query, degenerate triangles
// included, and the bounding-volume hierarchy against brute force.

#include "datasets/bvh.h"
#include "datasets/generators.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <string>

namespace mcf {
namespace {

TEST(ClosestPoint, RegionsOfOneTriangle) {
  const Eigen::Vector3d a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  auto cp = [&](double x, double y, double z) {
    return closest_point_on_triangle({x, y, z}, a, b, c);
  };
  EXPECT_TRUE(cp(-1, -1, 2).isApprox(a));                               // vertex A
  EXPECT_TRUE(cp(3, -1, 0).isApprox(b));                                // vertex B
  EXPECT_TRUE(cp(-0.5, 4, 1).isApprox(c));                              // vertex C
  EXPECT_TRUE(cp(0.5, -2, 1).isApprox(Eigen::Vector3d(0.5, 0, 0)));     // edge AB
  EXPECT_TRUE(cp(-3, 0.25, 0).isApprox(Eigen::Vector3d(0, 0.25, 0)));   // edge AC
  EXPECT_TRUE(cp(1, 1, -5).isApprox(Eigen::Vector3d(0.5, 0.5, 0)));     // edge BC
  EXPECT_TRUE(cp(0.2, 0.3, 7).isApprox(Eigen::Vector3d(0.2, 0.3, 0)));  // face
  // Degenerate (collinear) triangle: the nearest point of the segment.
  const Eigen::Vector3d q = closest_point_on_triangle({0.5, 1, 0}, a, b, Eigen::Vector3d(2, 0, 0));
  EXPECT_TRUE(q.isApprox(Eigen::Vector3d(0.5, 0, 0)));
}

/// Distance from p to the segment [s, e] in long double, by minimising |s + t(e - s) - p|² over
/// t in [0, 1] in closed form (a zero-length segment is its point): the reference for
/// degenerate triangles, whose point set is the union of their three edges.
long double segment_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& s,
                             const Eigen::Vector3d& e) {
  long double dd = 0, dp = 0;
  for (int k = 0; k < 3; ++k) {
    const long double d = (long double)e[k] - s[k], w = (long double)p[k] - s[k];
    dd += d * d;
    dp += d * w;
  }
  const long double t = dd > 0 ? std::clamp(dp / dd, 0.0L, 1.0L) : 0.0L;
  long double r = 0;
  for (int k = 0; k < 3; ++k) {
    const long double q = s[k] + t * ((long double)e[k] - s[k]) - p[k];
    r += q * q;
  }
  return std::sqrt(r);
}

long double edges_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                           const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  return std::min(
      {segment_distance(p, a, b), segment_distance(p, b, c), segment_distance(p, c, a)});
}

TEST(ClosestPoint, DegenerateTrianglesAreTheirEdges) {
  // a == b took edge AB's branch with a zero denominator and returned a (1.118 here, not 1).
  const Eigen::Vector3d o = Eigen::Vector3d::Zero(), x = Eigen::Vector3d::UnitX(), p0(0.5, 1, 0);
  EXPECT_NEAR((closest_point_on_triangle(p0, o, o, x) - p0).norm(), 1.0, 1e-15);
  EXPECT_NEAR((closest_point_on_triangle(p0, x, o, o) - p0).norm(), 1.0, 1e-15);
  EXPECT_NEAR((closest_point_on_triangle(p0, o, x, o) - p0).norm(), 1.0, 1e-15);

  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1, 1), t(-2, 2);
  auto random_point = [&] { return Eigen::Vector3d(u(rng), u(rng), u(rng)); };
  int checked = 0, wrong = 0;
  std::string first;
  auto check = [&](const char* kind, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                   const Eigen::Vector3d& c) {
    for (int i = 0; i < 4; ++i) {
      // Points around the triangle and next to it (on its line, and just off it).
      Eigen::Vector3d p = 2 * random_point();
      if (i % 2) p = a + t(rng) * (c - a + b - a) + 1e-3 * random_point();
      const Eigen::Vector3d q = closest_point_on_triangle(p, a, b, c);
      const double got = (q - p).norm(), want = double(edges_distance(p, a, b, c));
      // The distance, and the point lies on the triangle.
      if (!(std::abs(got - want) <= 1e-12 * (1 + want) && edges_distance(q, a, b, c) < 1e-12)) {
        if (wrong++ == 0) {
          std::ostringstream m;
          m.precision(17);
          m << kind << ": distance " << got << ", want " << want << " (p " << p.transpose()
            << ", a " << a.transpose() << ", b " << b.transpose() << ", c " << c.transpose() << ")";
          first = m.str();
        }
      }
      ++checked;
    }
  };
  for (int i = 0; i < 500; ++i) {
    const Eigen::Vector3d a = random_point(), b = random_point();
    check("a == b", a, a, b);
    check("b == c", b, a, a);
    check("a == c", a, b, a);
    check("all equal", a, a, a);
    // Collinear up to rounding: a + s·d with s not representable, the middle point at each corner.
    const Eigen::Vector3d d = random_point();
    const double s1 = t(rng), s2 = t(rng);
    const Eigen::Vector3d p1 = a + s1 * d, p2 = a + s2 * d;
    check("collinear", a, p1, p2);
    check("collinear", p1, a, p2);
    check("collinear", p1, p2, a);
    check("collinear (tenths)", a, a + 0.1 * d, a + 0.7 * d);
    check("collinear (thirds)", a + d / 3.0, a, a + 2.0 * d / 3.0);
  }
  EXPECT_EQ(checked, 500 * 9 * 4);
  EXPECT_EQ(wrong, 0) << "first: " << first;
}

TEST(TriangleBvh, ClosestPointEqualsBruteForce) {
  const TriangleMesh m = make_torus(1.0, 0.35, 60, 20);
  const TriangleBvh bvh(m.vertices, m.faces);
  EXPECT_GT(bvh.depth(), 5);
  EXPECT_LT(bvh.depth(), 16);  // balanced: ⌈log2(2400/4)⌉+1 = 11
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.8, 1.8);
  for (int i = 0; i < 2000; ++i) {
    // Mix far points, near-surface points and points inside the tube.
    Eigen::Vector3d p(u(rng), u(rng), u(rng));
    if (i % 3 == 1) p = m.vertices.row(i % m.num_vertices()).transpose() * (1.0 + 0.01 * u(rng));
    const ClosestHit fast = bvh.closest(p), slow = bvh.closest_brute_force(p);
    ASSERT_GE(fast.triangle, 0);
    EXPECT_NEAR(fast.squared_distance, slow.squared_distance, 1e-14 * (1 + slow.squared_distance))
        << i;
    const Eigen::Vector3d a = m.vertices.row(m.faces(fast.triangle, 0)),
                          b = m.vertices.row(m.faces(fast.triangle, 1)),
                          c = m.vertices.row(m.faces(fast.triangle, 2));
    EXPECT_NEAR((closest_point_on_triangle(p, a, b, c) - p).squaredNorm(), fast.squared_distance,
                1e-15);
  }
}

TEST(TriangleBvh, BoundExcludesFartherTriangles) {
  const TriangleMesh m = make_icosphere(2);
  const TriangleBvh bvh(m.vertices, m.faces);
  const ClosestHit none = bvh.closest(Eigen::Vector3d(3, 0, 0), 1.0);  // nearest is ~2 away
  EXPECT_EQ(none.triangle, -1);
  EXPECT_EQ(TriangleBvh(Positions(0, 3), Triangles(0, 3)).closest(Eigen::Vector3d::Zero()).triangle,
            -1);
}

}  // namespace
}  // namespace mcf
