// The per-cell kernel of SetSystemMatrices (bases/cell_blocks.h) against direct formulas: the
// piece frame against an Eigen construction, the 8x8 blocks against a plain triple loop.
#include "bases/cell_blocks.h"

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <random>

namespace mcf {
namespace {

TEST(PieceFrame, IsTheScaledOrthonormalFrameOfThePlane) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector3d p0(u(rng), u(rng), u(rng)), p1(u(rng), u(rng), u(rng)),
        p2(u(rng), u(rng), u(rng));
    const double scale = 1.0 + 10.0 * std::abs(u(rng));
    double f1[3], f2[3];
    const double len = piece_frame(p0.data(), p1.data(), p2.data(), scale, f1, f2);
    const Eigen::Vector3d cross = (p1 - p0).cross(p2 - p0);
    EXPECT_NEAR(len, cross.norm(), 1e-14);
    const Eigen::Vector3d e1 = (p1 - p0).normalized();
    const Eigen::Vector3d e2 = cross.normalized().cross(e1);
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(f1[a], scale * e1[a], 1e-13 * scale);
      EXPECT_NEAR(f2[a], scale * e2[a], 1e-13 * scale);
    }
  }
}

TEST(PieceFrame, DegeneratePiecesReturnZero) {
  const double a[3] = {0, 0, 0}, b[3] = {1, 1, 1}, c[3] = {2, 2, 2};
  double f1[3], f2[3];
  EXPECT_EQ(piece_frame(a, b, c, 1.0, f1, f2), 0.0);  // collinear
  EXPECT_EQ(piece_frame(a, a, c, 1.0, f1, f2), 0.0);  // repeated corner
}

// β_c(t) = Π_a (t_a or 1 - t_a) for corner c = x + 2y + 4z, ∇_t β_c by the product rule.
void trilinear(const double t[3], double val[8], double grad[8][3]) {
  for (int c = 0; c < 8; ++c) {
    double f[3], df[3];
    for (int a = 0; a < 3; ++a) {
      const bool hi = (c >> a) & 1;
      f[a] = hi ? t[a] : 1.0 - t[a];
      df[a] = hi ? 1.0 : -1.0;
    }
    val[c] = f[0] * f[1] * f[2];
    grad[c][0] = df[0] * f[1] * f[2];
    grad[c][1] = f[0] * df[1] * f[2];
    grad[c][2] = f[0] * f[1] * df[2];
  }
}

TEST(CellBlocks, MatchesDirectSumsOverManyPoints) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  CellBlocks<true, true> blocks;
  double M[8][8] = {}, K[8][8] = {};
  // More points than one batch, so that the register accumulation is flushed several times.
  for (int q = 0; q < 3 * CellBlocks<true, true>::kBatch + 5; ++q) {
    const double t[3] = {u(rng), u(rng), u(rng)};
    const double f1[3] = {u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5};
    const double f2[3] = {u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5};
    const double wm = u(rng), s11 = 1.0 + u(rng), s12 = u(rng) - 0.5, s22 = 1.0 + u(rng);
    blocks.add(t, f1, f2, wm, s11, s12, s22);
    double val[8], grad[8][3];
    trilinear(t, val, grad);
    for (int a = 0; a < 8; ++a)
      for (int b = 0; b < 8; ++b) {
        const double ea = f1[0] * grad[a][0] + f1[1] * grad[a][1] + f1[2] * grad[a][2];
        const double ma = f2[0] * grad[a][0] + f2[1] * grad[a][1] + f2[2] * grad[a][2];
        const double eb = f1[0] * grad[b][0] + f1[1] * grad[b][1] + f1[2] * grad[b][2];
        const double mb = f2[0] * grad[b][0] + f2[1] * grad[b][1] + f2[2] * grad[b][2];
        M[a][b] += wm * val[a] * val[b];
        K[a][b] += ea * (s11 * eb + s12 * mb) + ma * (s12 * eb + s22 * mb);
      }
  }
  blocks.finish();
  for (int a = 0; a < 8; ++a)
    for (int b = a; b < 8; ++b) {
      EXPECT_NEAR(blocks.mass(a, b), M[a][b], 1e-13) << a << "," << b;
      EXPECT_NEAR(blocks.stiffness(a, b), K[a][b], 1e-13) << a << "," << b;
    }
}

}  // namespace
}  // namespace mcf
