// The floor model (solvers/phase_floor.h) against counts made by hand on a tiny system: A the
// 3 x 3 tridiagonal (2, -1) matrix (7 entries, 4 off the diagonal), P the 3 x 2 linear
// prolongation [1 0; 1/2 1/2; 0 1] (4 entries), C = Pᵀ A P (2 x 2, full).

#include "solvers/phase_floor.h"

#include <gtest/gtest.h>

#include <vector>

namespace {

using mcf::SparseMatrix;

struct Tiny {
  SparseMatrix A{3, 3}, P{3, 2}, C;
  Tiny() {
    std::vector<Eigen::Triplet<double, int>> a{{0, 0, 2},  {1, 1, 2},  {2, 2, 2}, {0, 1, -1},
                                               {1, 0, -1}, {1, 2, -1}, {2, 1, -1}};
    A.setFromTriplets(a.begin(), a.end());
    std::vector<Eigen::Triplet<double, int>> p{{0, 0, 1}, {1, 0, 0.5}, {1, 1, 0.5}, {2, 1, 1}};
    P.setFromTriplets(p.begin(), p.end());
    C = SparseMatrix(P.transpose() * A * P);
    A.makeCompressed();
    P.makeCompressed();
    C.makeCompressed();
  }
};

TEST(PhaseFloor, SizesOfACompressedMatrix) {
  const Tiny t;
  const mcf::SparseSize s = mcf::sparse_size(t.P);
  EXPECT_EQ(s.rows, 3);
  EXPECT_EQ(s.cols, 2);
  EXPECT_EQ(s.nnz, 4);
  EXPECT_EQ(s.index_bytes, 4);
  EXPECT_EQ(s.value_bytes, 8);
}

// Four interleaved columns (the multigrid's padded x, y, z block).
TEST(PhaseFloor, LevelKernelsMatchHandCounts) {
  const Tiny t;
  const auto A = mcf::sparse_size(t.A), P = mcf::sparse_size(t.P);
  // Residual: 7 entries x 12 bytes + 4 pointers x 4 bytes + b, x read and r written (3 x 3 x 4
  // doubles); 7 multiply-adds per column.
  const mcf::PhaseCost r = mcf::residual_cost(A, 4);
  EXPECT_EQ(r.bytes, 84 + 16 + 288);
  EXPECT_EQ(r.flops, 56);
  // Sweep: the 4 off-diagonal entries, the pointers, the inverse diagonal (3 doubles), b read and
  // x read and written; 4 multiply-adds and 3 scalings per column.
  const mcf::PhaseCost g = mcf::sweep_cost(A, 4, 4);
  EXPECT_EQ(g.bytes, 48 + 16 + 24 + 288);
  EXPECT_EQ(g.flops, (8 + 3) * 4);
  // A sweep on single-precision values with 16-bit offsets: 6 bytes an entry.
  mcf::SparseSize compact = A;
  compact.index_bytes = 2;
  compact.value_bytes = 4;
  EXPECT_EQ(mcf::sweep_cost(compact, 4, 4).bytes, 24 + 16 + 24 + 288);
  // Restriction: P (4 x 12 bytes, 3 column pointers), the fine residual read (3 rows), the
  // coarse right-hand side and the coarse start (zero) written (2 rows each).
  const mcf::PhaseCost rs = mcf::restriction_cost(P, 4);
  EXPECT_EQ(rs.bytes, 48 + 12 + 7 * 32);
  EXPECT_EQ(rs.flops, 32);
  // Prolongation: Pᵀ (4 pointers over the fine rows), x_c read, x read and written.
  const mcf::PhaseCost pr = mcf::prolongation_cost(P, 4);
  EXPECT_EQ(pr.bytes, 48 + 16 + 8 * 32);
  EXPECT_EQ(pr.flops, (8 + 3) * 4);
}

TEST(PhaseFloor, GalerkinMatchesHandCounts) {
  const Tiny t;
  // Column 0 of C: v = A (P e_0) reads A's columns 0 and 1 (2 + 3 entries); the upper entry (0, 0)
  // is P e_0 · v (2 entries). Column 1: A's columns 1 and 2 (3 + 2); entries (0, 1) and (1, 1), 2
  // each. 16 multiply-adds.
  EXPECT_EQ(mcf::galerkin_flops(t.A, t.P, t.C), 32);
  const mcf::PhaseCost c =
      mcf::galerkin_cost(mcf::sparse_size(t.A), mcf::sparse_size(t.P), mcf::sparse_size(t.C), 32);
  EXPECT_EQ(c.bytes, (84 + 16) + (48 + 12) + 4 * 12);
  EXPECT_EQ(c.flops, 32);
}

TEST(PhaseFloor, OtherPhasesMatchHandCounts) {
  const mcf::PhaseCost f = mcf::factor_solve_cost(3, 5, 4);
  EXPECT_EQ(f.bytes, 2 * 5 * 12 + 24 + 2 * 3 * 32);
  EXPECT_EQ(f.flops, (20 + 3) * 4);
  const mcf::PhaseCost s = mcf::matrix_sum_cost(7);
  EXPECT_EQ(s.bytes, 3 * 7 * 8);
  EXPECT_EQ(s.flops, 21);
  const mcf::PhaseCost a = mcf::assembly_cost(1, 3, 9, 2, 30);
  EXPECT_EQ(a.bytes, 12 + 72 + 144);
  EXPECT_EQ(a.flops, 30);
  EXPECT_EQ(mcf::assembly_cost(1, 3, 9, 1, 30).bytes, 12 + 72 + 72);
  // The tracked update: 1000 preprocessed bytes, 5 coefficients, 2 matrices of 9 entries, 10
  // points of 50 flops.
  const mcf::PhaseCost u = mcf::integration_cost(1000, 5, 9, 2, 10, 50);
  EXPECT_EQ(u.bytes, 1000 + 120 + 144);
  EXPECT_EQ(u.flops, 500);
  // Evaluation: 2 vertices of 8 weights (with their indices) from 5 coefficients, 3 columns.
  const mcf::PhaseCost e = mcf::stencil_cost(2, 8, 5, 3);
  EXPECT_EQ(e.bytes, 2 * 8 * 12 + 5 * 24 + 2 * 24);
  EXPECT_EQ(e.flops, 96);
  EXPECT_EQ(mcf::copy_cost(3, 4).bytes, 192);
  EXPECT_EQ(mcf::copy_cost(3, 4).flops, 0);
  mcf::PhaseCost sum = f;
  sum += s;
  EXPECT_EQ(sum.bytes, f.bytes + s.bytes);
  EXPECT_EQ((2.0 * s).flops, 42);
}

TEST(PhaseFloor, FloorIsTheSlowerOfMemoryAndCompute) {
  EXPECT_EQ(mcf::floor_seconds({100, 50}, 10, 100), 10);    // memory-bound
  EXPECT_EQ(mcf::floor_seconds({100, 5000}, 10, 100), 50);  // compute-bound
  EXPECT_EQ(mcf::floor_seconds({100, 5000}, 10, 0), 10);    // no peak given: bytes alone
}

}  // namespace
