#include "bases/cubature.h"

#include <gtest/gtest.h>

#include <Eigen/Core>

#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

namespace {

double factorial(int n) {
  return n <= 1 ? 1.0 : n * factorial(n - 1);
}

// ∫ x^a y^b over the reference triangle (0,0),(1,0),(0,1).
double reference_exact(int a, int b) {
  return factorial(a) * factorial(b) / factorial(a + b + 2);
}

double reference_cubature(const mcf::CubatureRule& r, int a, int b) {
  double s = 0.0;
  for (int q = 0; q < r.size(); ++q)
    s += r.weights[q] * std::pow(r.points[q][1], a) * std::pow(r.points[q][2], b);
  return 0.5 * s;
}

// Polynomials in (ξ,η) as dense coefficient grids c(i,j) of ξ^i η^j.
using Poly = Eigen::MatrixXd;
Poly mul(const Poly& p, const Poly& q) {
  Poly r = Poly::Zero(p.rows() + q.rows() - 1, p.cols() + q.cols() - 1);
  for (int i = 0; i < p.rows(); ++i)
    for (int j = 0; j < p.cols(); ++j)
      for (int k = 0; k < q.rows(); ++k)
        for (int l = 0; l < q.cols(); ++l) r(i + k, j + l) += p(i, j) * q(k, l);
  return r;
}

// Exact ∫_T x^a y^b over the triangle T = (v0, v1, v2) in the plane, through the affine map from
// the reference triangle: ∫_T f = 2|T| ∫_ref f∘F.
double triangle_exact(const Eigen::Vector2d v[3], int a, int b) {
  Poly X = Poly::Zero(2, 2), Y = Poly::Zero(2, 2);
  X(0, 0) = v[0].x();
  X(1, 0) = v[1].x() - v[0].x();
  X(0, 1) = v[2].x() - v[0].x();
  Y(0, 0) = v[0].y();
  Y(1, 0) = v[1].y() - v[0].y();
  Y(0, 1) = v[2].y() - v[0].y();
  Poly f = Poly::Ones(1, 1);
  for (int i = 0; i < a; ++i) f = mul(f, X);
  for (int i = 0; i < b; ++i) f = mul(f, Y);
  double s = 0.0;
  for (int i = 0; i < f.rows(); ++i)
    for (int j = 0; j < f.cols(); ++j) s += f(i, j) * reference_exact(i, j);
  const double jac =
      std::abs((v[1] - v[0]).x() * (v[2] - v[0]).y() - (v[1] - v[0]).y() * (v[2] - v[0]).x());
  return jac * s;
}

double triangle_cubature(const mcf::CubatureRule& r, const Eigen::Vector2d v[3], int a, int b) {
  const double area =
      0.5 * std::abs((v[1] - v[0]).x() * (v[2] - v[0]).y() - (v[1] - v[0]).y() * (v[2] - v[0]).x());
  double s = 0.0;
  for (int q = 0; q < r.size(); ++q) {
    const Eigen::Vector2d p = r.points[q][0] * v[0] + r.points[q][1] * v[1] + r.points[q][2] * v[2];
    s += r.weights[q] * std::pow(p.x(), a) * std::pow(p.y(), b);
  }
  return area * s;
}

TEST(Cubature, RulesAreNormalised) {
  for (int order : {1, 3, 6}) {
    const auto& r = mcf::cubature_rule(order);
    EXPECT_EQ(r.order, order);
    ASSERT_EQ(r.points.size(), r.weights.size());
    double ws = 0.0;
    for (int q = 0; q < r.size(); ++q) {
      ws += r.weights[q];
      EXPECT_GT(r.weights[q], 0.0);
      EXPECT_NEAR(r.points[q][0] + r.points[q][1] + r.points[q][2], 1.0, 1e-15);
      for (double b : r.points[q]) EXPECT_GE(b, 0.0);
    }
    EXPECT_NEAR(ws, 1.0, 1e-15);
  }
  EXPECT_EQ(mcf::cubature_rule(1).size(), 1);
  EXPECT_EQ(mcf::cubature_rule(3).size(), 3);
  EXPECT_EQ(mcf::cubature_rule(6).size(), 12);
  EXPECT_EQ(mcf::cubature_rule(1).degree, 1);
  EXPECT_EQ(mcf::cubature_rule(3).degree, 2);
  EXPECT_EQ(mcf::cubature_rule(6).degree, 6);
  // The paper's 3-point rule: midpoints between the vertices and the centroid.
  EXPECT_DOUBLE_EQ(mcf::cubature_rule(3).points[0][0], 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(mcf::cubature_rule(3).points[0][1], 1.0 / 6.0);
}

TEST(Cubature, InvalidOrderThrows) {
  EXPECT_THROW(mcf::cubature_rule(2), std::invalid_argument);
  EXPECT_THROW(mcf::cubature_rule(0), std::invalid_argument);
  EXPECT_THROW(mcf::cubature_rule(7), std::invalid_argument);
}

TEST(Cubature, ExactOnReferenceTriangleUpToDegree) {
  for (int order : {1, 3, 6}) {
    const auto& r = mcf::cubature_rule(order);
    for (int a = 0; a <= r.degree; ++a)
      for (int b = 0; a + b <= r.degree; ++b)
        EXPECT_NEAR(reference_cubature(r, a, b), reference_exact(a, b),
                    1e-13 * reference_exact(a, b))
            << "order " << order << " x^" << a << " y^" << b;
  }
}

TEST(Cubature, NotExactBeyondDegree) {
  // Some monomial of degree+1 must fail, else the degree claim (and the test above) is vacuous.
  for (int order : {1, 3, 6}) {
    const auto& r = mcf::cubature_rule(order);
    double worst = 0.0;
    for (int a = 0; a <= r.degree + 1; ++a) {
      const int b = r.degree + 1 - a;
      worst = std::max(worst, std::abs(reference_cubature(r, a, b) - reference_exact(a, b)) /
                                  reference_exact(a, b));
    }
    EXPECT_GT(worst, 1e-6) << "order " << order;
  }
}

TEST(Cubature, ExactOnRandomTriangles) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::Vector2d v[3] = {{u(rng), u(rng)}, {u(rng), u(rng)}, {u(rng), u(rng)}};
    for (int order : {1, 3, 6}) {
      const auto& r = mcf::cubature_rule(order);
      for (int a = 0; a <= r.degree; ++a)
        for (int b = 0; a + b <= r.degree; ++b) {
          const double exact = triangle_exact(v, a, b);
          // Scale for the tolerance: ∫|x|^a|y|^b ≤ area · max|x|^a|y|^b ≤ area · 2^(a+b).
          const double scale = triangle_exact(v, 0, 0) * std::pow(2.0, a + b);
          EXPECT_NEAR(triangle_cubature(r, v, a, b), exact, 1e-12 * scale)
              << "order " << order << " a " << a << " b " << b;
        }
    }
  }
}

}  // namespace
