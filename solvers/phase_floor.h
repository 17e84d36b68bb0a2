#pragma once
// The floor of a step's phases (docs/benchmarks.md "Floors"): the bytes a phase must move between
// memory and the processor and the floating-point operations it must do, from the sizes of the
// matrices it works on. A phase can take no less than max(bytes / bandwidth, flops / peak); the
// micro-benchmarks report their time as a multiple of that.
//
// The model counts compulsory traffic only: every array the phase reads is read once, every array
// it writes is written once (no write-allocate read, as STREAM counts), caches hold nothing
// between phases. Index arrays count `index_bytes` an entry, values `value_bytes`; a compressed
// column (or row) pointer array of n + 1 entries counts 4 bytes each. Vectors of right-hand sides
// are `columns` doubles a row (the multigrid's interleaved blocks: padded to a multiple of 4). A
// multiply-add counts 2 flops. The formulas, with A an n x n matrix of nnz entries, P an n_f x n_c
// prolongation of nnz_P entries, c columns, ib index bytes, vb value bytes:
//
//   residual r = b - A x       bytes (nnz (ib + vb) + 4 (n + 1)) + 3 n c 8       flops 2 nnz c
//   Gauss-Seidel sweep         bytes (nnz_off (ib + vb) + 4 (n + 1)) + n 8       flops 2 nnz_off c
//                                    (inverse diagonal) + 3 n c 8 (b; x read, x written)  + n c
//   restriction b_c = Pᵀ r     bytes nnz_P (4 + 8) + 4 (n_c + 1) + (n_f + 2 n_c) c 8
//     (and the coarse start x_c = 0 written in the same pass)            flops 2 nnz_P c
//   prolongation x += P x_c    bytes nnz_P (4 + 8) + 4 (n_f + 1) + (n_c + 2 n_f) c 8
//                                                                          flops (2 nnz_P + n_f) c
//   Galerkin A_c = Pᵀ A P      bytes nnz_A (4 + 8) + 4 (n_f + 1) + nnz_P (4 + 8) + 4 (n_c + 1)
//                                    + nnz_C (4 + 8) (pattern read, values written)
//                              flops galerkin_flops(): the product's multiply-adds
//   direct solve with L D Lᵀ   bytes 2 nnz_L (4 + 8) + n 8 + 2 n c 8          flops (4 nnz_L + n) c
//   sum a M + b K on a pattern bytes 3 nnz 8 (M, K read; sum written)           flops 3 nnz
//   assembly of m matrices     bytes faces 3 4 + vertices 3 8 + m nnz 8 (the values written)
//                              flops faces × flops_per_face (the caller's count of its formula)
//   integration at points      bytes input + coefficients 3 8 + m nnz 8
//                              flops points × flops_per_point
//                              (the tracked octree's update: `input` its preprocessed bytes)
//   stencil evaluation         bytes v w (4 + 8) + coefficients c 8 + v c 8   flops 2 v w c
//                              (v output rows, w weights each, read once with their indices)
//   copy of n x c doubles      bytes 2 n c 8                                    flops 0
//
// Values and inputs are counts (no matrices), so the model is tested against hand counts on a
// tiny matrix (tests/solvers/test_phase_floor.cpp) and the benchmarks feed it the sizes of the
// matrices they time (benchmarks/micro_floor.cpp).

#include "core/sparse.h"

#include <cstdint>

namespace mcf {

/// What a phase must move and compute.
struct PhaseCost {
  double bytes = 0.0;
  double flops = 0.0;
  PhaseCost& operator+=(const PhaseCost& o) {
    bytes += o.bytes;
    flops += o.flops;
    return *this;
  }
  friend PhaseCost operator*(double times, PhaseCost c) {
    c.bytes *= times;
    c.flops *= times;
    return c;
  }
};

/// A compressed sparse matrix's size as the floor model reads it.
struct SparseSize {
  std::int64_t rows = 0;
  std::int64_t cols = 0;
  std::int64_t nnz = 0;
  int index_bytes = 4;  ///< bytes of one stored row index (or 16-bit offset: 2)
  int value_bytes = 8;  ///< bytes of one stored value (single precision: 4)
};

/// The size of A as stored in compressed column form (int indices, double values).
SparseSize sparse_size(const SparseRef& A);

/// Inputs: A (square), `off_diagonal` entries read by a sweep (nnz minus the diagonal entries),
/// columns of the right-hand-side block.
PhaseCost residual_cost(const SparseSize& A, int columns);
PhaseCost sweep_cost(const SparseSize& A, std::int64_t off_diagonal, int columns);
/// P is n_f x n_c.
PhaseCost restriction_cost(const SparseSize& P, int columns);
PhaseCost prolongation_cost(const SparseSize& P, int columns);
/// A (n_f x n_f), P (n_f x n_c), C = Pᵀ A P (n_c x n_c); flops from galerkin_flops().
PhaseCost galerkin_cost(const SparseSize& A, const SparseSize& P, const SparseSize& C,
                        double flops);
/// The multiply-adds of solvers/galerkin.h's galerkin_values, 2 flops each: per coarse column J,
/// v = A P e_J (nnz of A's column t for every entry (t, J) of P), then one sparse dot product
/// P e_I · v per upper entry (I <= J) of C (nnz of P's column I).
double galerkin_flops(const SparseRef& A, const SparseRef& P, const SparseRef& C);
/// Forward and backward substitution with a factor of `factor_nnz` entries (n x n), c columns.
PhaseCost factor_solve_cost(std::int64_t n, std::int64_t factor_nnz, int columns);
PhaseCost matrix_sum_cost(std::int64_t nnz);
/// `matrices` matrices of `nnz` entries each (M alone: 1; M and K: 2) integrated over `faces`
/// triangles from `vertices` positions.
PhaseCost assembly_cost(std::int64_t faces, std::int64_t vertices, std::int64_t nnz, int matrices,
                        double flops_per_face);
PhaseCost integration_cost(double input_bytes, std::int64_t coefficients, std::int64_t nnz,
                           int matrices, std::int64_t points, double flops_per_point);
PhaseCost stencil_cost(std::int64_t outputs, int weights, std::int64_t coefficients, int columns);
PhaseCost copy_cost(std::int64_t rows, int columns);

/// The phase's floor in seconds: max(bytes / bandwidth, flops / peak), bandwidth in bytes/s and
/// peak in flops/s (a peak <= 0: bytes alone).
double floor_seconds(const PhaseCost& cost, double bandwidth, double peak_flops);

}  // namespace mcf
