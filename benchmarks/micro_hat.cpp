// Micro-benchmarks of the hat basis and the direct/iterative solvers on a paper-sized mesh
// (docs/benchmarks.md): hat assembly, CHOLMOD refactorization + solve, PCG solve.
// Mesh: $MCFBENCH_BENCH_MESH (default cgal:armadillo@faces=832000).

#include "bases/hat_basis.h"
#include "datasets/mesh_spec.h"
#include "solvers/cholmod_solver.h"
#include "solvers/pcg_solver.h"
#include "solvers/symmetric_multiply.h"

#include <benchmark/benchmark.h>

#include <cstdlib>
#include <memory>

namespace mcf {
namespace {

struct HatFixture {
  MeshSource source;
  std::unique_ptr<HatBasis> basis;
  SparseMatrix system;  // M + δK, δ = 1e-3 on the unit-cube model
  Eigen::MatrixXd rhs;

  static HatFixture& get() {
    static HatFixture f = [] {
      HatFixture h;
      const char* spec = std::getenv("MCFBENCH_BENCH_MESH");
      h.source = load_mesh_spec(spec ? spec : "cgal:armadillo@faces=832000");
      h.basis = std::make_unique<HatBasis>(h.source.mesh);
      h.system = h.basis->mass() + 1e-3 * h.basis->stiffness();
      symmetric_multiply(h.basis->mass(), h.source.mesh.vertices, h.rhs);
      return h;
    }();
    return f;
  }
};

void label(benchmark::State& state, const HatFixture& f) {
  state.counters["vertices"] = double(f.source.mesh.num_vertices());
  state.counters["faces"] = double(f.source.mesh.num_faces());
}

void BM_HatAssembly(benchmark::State& state) {
  auto& f = HatFixture::get();
  const Coefficients x = f.source.mesh.vertices;
  for (auto _ : state) {
    f.basis->update(x, true, true);
    benchmark::DoNotOptimize(f.basis->stiffness().valuePtr());
  }
  label(state, f);
}
BENCHMARK(BM_HatAssembly)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_CholmodRefactorizeSolve(benchmark::State& state) {
  auto& f = HatFixture::get();
  CholmodSolver solver;
  solver.set_matrix(f.system);  // symbolic analysis outside the timed loop
  Eigen::MatrixXd X;
  for (auto _ : state) {
    solver.set_matrix(f.system);
    solver.solve(f.rhs, X);
  }
  state.counters["analyses"] = solver.analyses();
  state.counters["factor_nnz"] = double(solver.factor_nonzeros());
  label(state, f);
}
BENCHMARK(BM_CholmodRefactorizeSolve)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_PcgSolve(benchmark::State& state) {
  auto& f = HatFixture::get();
  PcgOptions o;
  o.relative_tolerance = 1e-8;
  o.preconditioner =
      state.range(0) == 0 ? PcgPreconditioner::jacobi : PcgPreconditioner::incomplete_cholesky;
  PcgSolver solver(o);
  int iterations = 0;
  for (auto _ : state) {
    solver.set_matrix(f.system);
    // Warm start from the previous step's positions, as in a flow.
    Eigen::MatrixXd X = f.source.mesh.vertices;
    iterations = solver.solve(f.rhs, X).iterations;
  }
  state.counters["iterations"] = iterations;
  state.SetLabel(state.range(0) == 0 ? "jacobi" : "ichol");
  label(state, f);
}
BENCHMARK(BM_PcgSolve)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace mcf
