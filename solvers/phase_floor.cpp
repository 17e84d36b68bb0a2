#include "solvers/phase_floor.h"

#include "solvers/csc_view.h"

#include <algorithm>

namespace mcf {

namespace {
constexpr double kDouble = 8.0;
constexpr double kPointer = 4.0;  // one entry of a column (row) pointer array

/// A compressed matrix's arrays: its entries and its pointer array over `major` columns.
double matrix_bytes(const SparseSize& A, std::int64_t nnz, std::int64_t major) {
  return double(nnz) * (A.index_bytes + A.value_bytes) + kPointer * double(major + 1);
}
}  // namespace

SparseSize sparse_size(const SparseRef& A) {
  SparseSize s;
  s.rows = A.rows();
  s.cols = A.cols();
  s.nnz = A.nonZeros();
  s.index_bytes = int(sizeof(int));
  s.value_bytes = int(sizeof(double));
  return s;
}

PhaseCost residual_cost(const SparseSize& A, int columns) {
  const double n = double(A.rows), c = columns;
  return {matrix_bytes(A, A.nnz, A.cols) + 3 * n * c * kDouble, 2 * double(A.nnz) * c};
}

PhaseCost sweep_cost(const SparseSize& A, std::int64_t off_diagonal, int columns) {
  const double n = double(A.rows), c = columns;
  return {matrix_bytes(A, off_diagonal, A.cols) + n * kDouble + 3 * n * c * kDouble,
          (2 * double(off_diagonal) + n) * c};
}

PhaseCost restriction_cost(const SparseSize& P, int columns) {
  const double c = columns;
  return {matrix_bytes(P, P.nnz, P.cols) + double(P.rows + 2 * P.cols) * c * kDouble,
          2 * double(P.nnz) * c};
}

PhaseCost prolongation_cost(const SparseSize& P, int columns) {
  const double c = columns;
  return {matrix_bytes(P, P.nnz, P.rows) + double(P.cols + 2 * P.rows) * c * kDouble,
          (2 * double(P.nnz) + double(P.rows)) * c};
}

PhaseCost galerkin_cost(const SparseSize& A, const SparseSize& P, const SparseSize& C,
                        double flops) {
  return {matrix_bytes(A, A.nnz, A.cols) + matrix_bytes(P, P.nnz, P.cols) +
              double(C.nnz) * (C.index_bytes + C.value_bytes),
          flops};
}

double galerkin_flops(const SparseRef& Am, const SparseRef& Pm, const SparseRef& Cm) {
  const multigrid_detail::Csc A(Am), P(Pm), C(Cm);
  double madds = 0;
  for (int J = 0; J < P.cols; ++J) {
    for (int p = P.outer[J]; p < P.outer[J + 1]; ++p) {
      const int t = P.inner[p];
      madds += A.outer[t + 1] - A.outer[t];
    }
    for (int e = C.outer[J]; e < C.outer[J + 1]; ++e) {
      const int I = C.inner[e];
      if (I <= J) madds += P.outer[I + 1] - P.outer[I];
    }
  }
  return 2 * madds;
}

PhaseCost factor_solve_cost(std::int64_t n, std::int64_t factor_nnz, int columns) {
  const double c = columns;
  return {
      2 * double(factor_nnz) * (4 + kDouble) + double(n) * kDouble + 2 * double(n) * c * kDouble,
      (4 * double(factor_nnz) + double(n)) * c};
}

PhaseCost matrix_sum_cost(std::int64_t nnz) {
  return {3 * double(nnz) * kDouble, 3 * double(nnz)};
}

PhaseCost assembly_cost(std::int64_t faces, std::int64_t vertices, std::int64_t nnz, int matrices,
                        double flops_per_face) {
  return {double(faces) * 3 * 4 + double(vertices) * 3 * kDouble +
              double(matrices) * double(nnz) * kDouble,
          double(faces) * flops_per_face};
}

PhaseCost integration_cost(double input_bytes, std::int64_t coefficients, std::int64_t nnz,
                           int matrices, std::int64_t points, double flops_per_point) {
  return {
      input_bytes + double(coefficients) * 3 * kDouble + double(matrices) * double(nnz) * kDouble,
      double(points) * flops_per_point};
}

PhaseCost stencil_cost(std::int64_t outputs, int weights, std::int64_t coefficients, int columns) {
  const double v = double(outputs), w = weights, c = columns;
  return {v * w * (4 + kDouble) + double(coefficients) * c * kDouble + v * c * kDouble,
          2 * v * w * c};
}

PhaseCost copy_cost(std::int64_t rows, int columns) {
  return {2 * double(rows) * columns * kDouble, 0.0};
}

double floor_seconds(const PhaseCost& cost, double bandwidth, double peak_flops) {
  const double memory = bandwidth > 0 ? cost.bytes / bandwidth : 0.0;
  const double compute = peak_flops > 0 ? cost.flops / peak_flops : 0.0;
  return std::max(memory, compute);
}

}  // namespace mcf
