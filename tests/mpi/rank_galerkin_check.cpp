// Under mpirun: the distributed multigrid's coarse operators (distributed/rank_multigrid.h, its
// own Galerkin products on each rank's rows with the ghosts' prolongation rows exchanged) equal
// PETSc's parallel MatPtAP of the same prolongations, level by level, to rounding; and CG by its
// cycle solves a system with known solution. The fine operator is a weighted graph Laplacian
// plus a mass-like diagonal on a sphere's mesh, partitioned as the distributed flow partitions
// it; the cycle is a symmetric operator. Exit 0 when all hold, 1 otherwise (a message on rank 0).

#include "datasets/generators.h"
#include "distributed/comm.h"
#include "distributed/rank_block_cg.h"
#include "distributed/rank_mesh.h"
#include "distributed/rank_multigrid.h"
#include "solvers/petsc_runtime.h"

#include <petscmat.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <vector>

using namespace mcf;
using namespace mcf::dist;

namespace {

/// A PETSc matrix from this rank's rows as global entries.
Mat petsc_matrix(const std::vector<RankMultigrid::Entry>& entries, int rows, int cols) {
  Mat m = nullptr;
  petsc_check(MatCreate(PETSC_COMM_WORLD, &m), "MatCreate");
  petsc_check(MatSetSizes(m, rows, cols, PETSC_DETERMINE, PETSC_DETERMINE), "MatSetSizes");
  petsc_check(MatSetType(m, MATMPIAIJ), "MatSetType");
  petsc_check(MatMPIAIJSetPreallocation(m, 40, nullptr, 40, nullptr), "preallocation");
  petsc_check(MatSetOption(m, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE), "MatSetOption");
  for (const auto& e : entries) {
    const PetscInt r = PetscInt(e.row), c = PetscInt(e.column);
    petsc_check(MatSetValues(m, 1, &r, 1, &c, &e.value, INSERT_VALUES), "MatSetValues");
  }
  petsc_check(MatAssemblyBegin(m, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
  petsc_check(MatAssemblyEnd(m, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
  return m;
}

/// Largest |ours - PETSc's| over this rank's rows (entries absent on one side count as zero),
/// and the largest |entry|.
std::pair<double, double> difference(Mat petsc, const std::vector<RankMultigrid::Entry>& ours,
                                     long long first, int rows) {
  std::map<std::pair<long long, long long>, double> mine;
  for (const auto& e : ours) mine[{e.row, e.column}] += e.value;
  double diff = 0, scale = 0;
  for (int i = 0; i < rows; ++i) {
    const PetscInt row = PetscInt(first + i);
    PetscInt count = 0;
    const PetscInt* cols = nullptr;
    const PetscScalar* vals = nullptr;
    petsc_check(MatGetRow(petsc, row, &count, &cols, &vals), "MatGetRow");
    for (PetscInt k = 0; k < count; ++k) {
      auto it = mine.find({row, cols[k]});
      const double v = it == mine.end() ? 0.0 : it->second;
      if (it != mine.end()) mine.erase(it);
      diff = std::max(diff, std::abs(v - vals[k]));
      scale = std::max(scale, std::abs(vals[k]));
    }
    petsc_check(MatRestoreRow(petsc, row, &count, &cols, &vals), "MatRestoreRow");
  }
  for (const auto& [key, v] : mine) diff = std::max(diff, std::abs(v));  // ours only
  return {max_over_ranks(diff), max_over_ranks(scale)};
}

}  // namespace

int main() {
  PetscRuntime::instance();
  const TriangleMesh whole = rank() == 0 ? make_sphere(12000) : TriangleMesh{};
  const RankMesh mesh = scatter_mesh(whole);
  // The fine operator: weights w_ij = 1 + ((i + j) mod 7) / 10 on the mesh's edges, a diagonal
  // of Σ_j w_ij + 0.01 (symmetric positive definite), on the owned rows.
  std::vector<std::set<std::int64_t>> neighbours(std::size_t(mesh.owned));
  for (Eigen::Index f = 0; f < mesh.faces.rows(); ++f)
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) {
        const int i = mesh.faces(f, a), j = mesh.faces(f, b);
        if (i != j && i < mesh.owned) neighbours[std::size_t(i)].insert(mesh.global(j));
      }
  std::vector<RankMultigrid::Entry> fine;
  for (int i = 0; i < mesh.owned; ++i) {
    const long long gi = mesh.global(i);
    double sum = 0.01;
    for (const std::int64_t gj : neighbours[std::size_t(i)]) {
      const double w = 1.0 + double((gi + gj) % 7) / 10.0;
      fine.push_back({gi, gj, -w});
      sum += w;
    }
    fine.push_back({gi, gi, sum});
  }
  Mat A = petsc_matrix(fine, mesh.owned, mesh.owned);
  RankMultigrid multigrid(mesh, RankCycle{false, 2});
  multigrid.set_operator(A);
  multigrid.set_operator(A);  // the numeric product again, on the patterns made once
  bool ok = multigrid.levels() > 2;
  Mat previous = A;
  std::vector<Mat> made;
  for (int l = multigrid.levels() - 1; l > 0; --l) {
    const auto [fine_first, fine_rows] = multigrid.level_rows(l);
    const auto [first, rows] = multigrid.level_rows(l - 1);
    Mat P = petsc_matrix(multigrid.prolongation_entries(l), fine_rows, rows);
    Mat C = nullptr;
    petsc_check(MatPtAP(previous, P, MAT_INITIAL_MATRIX, PETSC_DEFAULT, &C), "MatPtAP");
    const auto [diff, scale] = difference(C, multigrid.operator_entries(l - 1), first, rows);
    const long long all_rows = sum_over_ranks((long long)rows);  // collective: on every rank
    if (rank() == 0)
      std::printf("level %d: %lld rows, |ours - MatPtAP| = %.3g of %.3g\n", l - 1, all_rows, diff,
                  scale);
    ok = ok && diff <= 1e-12 * scale;
    made.push_back(P);
    made.push_back(C);
    previous = C;
    (void)fine_first;
  }
  // The cycle (zero start) is a symmetric operator, as CG's preconditioner must be: u·B v = v·B u.
  {
    std::vector<double> u(4 * std::size_t(mesh.owned), 0.0), v(u.size(), 0.0), Bu(u.size(), 0.0),
        Bv(u.size(), 0.0);
    for (int i = 0; i < mesh.owned; ++i)
      for (int c = 0; c < 3; ++c) {
        const double g = double(mesh.global(i));
        u[4 * std::size_t(i) + std::size_t(c)] = std::cos(0.37 * g + c);
        v[4 * std::size_t(i) + std::size_t(c)] = std::sin(1.3 * g - 2.0 * c);
      }
    multigrid.cycle(u.data(), Bu.data());
    multigrid.cycle(v.data(), Bv.data());
    double vBu = 0, uBv = 0, norm = 0;
    for (std::size_t k = 0; k < u.size(); ++k) {
      vBu += v[k] * Bu[k];
      uBv += u[k] * Bv[k];
      norm += std::abs(v[k] * Bu[k]);
    }
    vBu = ordered_sum(vBu);
    uBv = ordered_sum(uBv);
    norm = ordered_sum(norm);
    if (rank() == 0)
      std::printf("the cycle's symmetry: |v.Bu - u.Bv| = %.2g of %.2g\n", std::abs(vBu - uBv),
                  norm);
    ok = ok && std::abs(vBu - uBv) <= 1e-12 * norm;
  }
  // CG by the cycle on A X = A X*, three columns.
  const int n = mesh.owned;
  std::vector<double> exact(4 * std::size_t(n), 0.0), B(exact.size(), 0.0), X(exact.size(), 0.0);
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c)
      exact[4 * std::size_t(i) + std::size_t(c)] = std::sin(double(mesh.global(i) * (c + 1)));
  multigrid.apply(exact.data(), B.data());
  const BlockCgReport cg = block_cg(multigrid, B.data(), X.data(), {true, true, true}, 1e-12, 200);
  const std::array<double, 3> rel = relative_residuals(multigrid, B.data(), X.data());
  double error = 0;
  for (std::size_t k = 0; k < X.size(); ++k) error = std::max(error, std::abs(X[k] - exact[k]));
  error = max_over_ranks(error);
  if (rank() == 0)
    std::printf(
        "CG by the V(2,2)-cycle: %d %d %d iterations, residuals %.2g %.2g %.2g, max error %.2g\n",
        cg.iterations[0], cg.iterations[1], cg.iterations[2], rel[0], rel[1], rel[2], error);
  for (int c = 0; c < 3; ++c)
    ok = ok && cg.converged[std::size_t(c)] && rel[std::size_t(c)] <= 1e-11 &&
         cg.iterations[std::size_t(c)] < 40;
  ok = ok && error < 1e-8;
  for (Mat& m : made) MatDestroy(&m);
  MatDestroy(&A);
  if (rank() == 0) std::printf("%s\n", ok ? "ok" : "FAILED");
  return ok ? 0 : 1;
}
