// Micro-benchmarks of the hat basis and the direct/iterative solvers on a paper-sized mesh
// (docs/benchmarks.md): hat assembly, CHOLMOD refactorization + solve, PCG solve, and the hat
// basis's multigrid (docs/surface-multigrid.md): the hierarchy's build, the Galerkin refresh of a
// step and one cycle.
// Mesh: $MCFBENCH_BENCH_MESH (default cgal:armadillo@faces=832000).

#include "bases/hat_basis.h"
#include "bases/surface_hierarchy.h"
#include "bases/vertex_ordering.h"
#include "datasets/mesh_spec.h"
#include "solvers/blas_threads.h"
#include "solvers/cholmod_solver.h"
#include "solvers/multigrid.h"
#include "solvers/pcg_solver.h"
#include "solvers/symmetric_multiply.h"

#include <benchmark/benchmark.h>

#include <cstdlib>
#include <map>
#include <memory>
#include <string>
#include <thread>

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

// The yardstick of the surface hierarchy's build: CHOLMOD's symbolic analysis of the same mesh
// (fill-reducing ordering and supernodal structure), timed as a fresh factorization (Arg 1: a
// new solver each time) less a refactorization on the analysed pattern (Arg 0).
void BM_CholmodAnalyzeFactorize(benchmark::State& state) {
  auto& f = HatFixture::get();
  const bool fresh = state.range(0) == 1;
  CholmodSolver kept;
  kept.set_matrix(f.system);
  for (auto _ : state) {
    if (fresh) {
      CholmodSolver solver;
      solver.set_matrix(f.system);
      benchmark::DoNotOptimize(solver.factor_nonzeros());
    } else {
      kept.set_matrix(f.system);
    }
  }
  label(state, f);
}
BENCHMARK(BM_CholmodAnalyzeFactorize)
    ->ArgName("fresh")
    ->Arg(1)
    ->Arg(0)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

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

namespace mcf {
namespace {

/// The hat basis with its hierarchy (functions in Cuthill–McKee order) on the same mesh.
struct HatMultigridFixture {
  std::unique_ptr<HatBasis> basis;
  SparseMatrix system;
  Eigen::MatrixXd rhs;

  static HatMultigridFixture& get() {
    static HatMultigridFixture f = [] {
      HatMultigridFixture h;
      const HatFixture& plain = HatFixture::get();
      h.basis = std::make_unique<HatBasis>(plain.source.mesh, MassKind::consistent,
                                           SurfaceHierarchyOptions{});
      h.system = h.basis->mass() + 1e-3 * h.basis->stiffness();
      symmetric_multiply(h.basis->mass(), h.basis->initial_coefficients(), h.rhs);
      return h;
    }();
    return f;
  }
  HierarchyView view() const { return {basis->prolongations(), basis->colours()}; }
};

void BM_SurfaceHierarchyBuild(benchmark::State& state) {
  const HatFixture& f = HatFixture::get();
  int levels = 0;
  for (auto _ : state) {
    const std::vector<int> order =
        bandwidth_ordering(f.source.mesh.faces, int(f.source.mesh.num_vertices()));
    benchmark::DoNotOptimize(order.data());
    const SurfaceHierarchy h = build_surface_hierarchy(f.source.mesh.vertices, f.source.mesh.faces);
    levels = h.levels();
  }
  state.counters["levels"] = levels;
  label(state, f);
}
BENCHMARK(BM_SurfaceHierarchyBuild)->Unit(benchmark::kMillisecond)->UseRealTime();

/// A step's set_matrix: the Galerkin values on the kept pattern and the coarsest factor.
void BM_HatMultigridSetMatrix(benchmark::State& state) {
  auto& f = HatMultigridFixture::get();
  MultigridSolver mg;
  mg.set_matrix(f.system, f.view());  // the pattern, outside the timed loop
  for (auto _ : state) mg.set_matrix(f.system, f.view());
  state.counters["levels"] = mg.levels();
  label(state, HatFixture::get());
}
BENCHMARK(BM_HatMultigridSetMatrix)->Unit(benchmark::kMillisecond)->UseRealTime();

/// One cycle from a warm start: Arg 0 a V(2,2)-cycle, 1 a W(5,5)-cycle.
void BM_HatMultigridCycle(benchmark::State& state) {
  auto& f = HatMultigridFixture::get();
  MultigridOptions o;
  o.cycle = state.range(0) == 0 ? MultigridCycle::V : MultigridCycle::W;
  o.pre_smooth = o.post_smooth = state.range(0) == 0 ? 2 : 5;
  o.cycles = 1;
  MultigridSolver mg(o);
  mg.set_matrix(f.system, f.view());
  const Eigen::MatrixXd start = f.basis->initial_coefficients();
  Eigen::MatrixXd X = start;
  mg.solve(f.rhs, X);  // first touch of the cycle's buffers
  double ratio = 0;
  for (auto _ : state) {
    X = start;
    const SolveReport r = mg.solve(f.rhs, X);
    ratio = r.residuals.empty() ? 0 : r.residuals.back();
  }
  state.counters["relative_residual"] = ratio;
  label(state, HatFixture::get());
}
BENCHMARK(BM_HatMultigridCycle)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace mcf

namespace mcf {
namespace {

/// CHOLMOD's refactorization and solve of the hat system against OpenBLAS's thread count, at two
/// sizes (Arg 0: the armadillo at 52k faces, 1: at 832k), so that a machine's own rule for
/// `--blas-threads` can be read off (docs/benchmarks.md, "BLAS threads").
void BM_CholmodBlasThreads(benchmark::State& state) {
  static std::map<int, std::pair<SparseMatrix, Eigen::MatrixXd>> systems;
  const int size = int(state.range(0));
  auto it = systems.find(size);
  if (it == systems.end()) {
    const MeshSource m =
        load_mesh_spec(size == 0 ? "cgal:armadillo" : "cgal:armadillo@faces=832000");
    const HatBasis basis(m.mesh);
    SparseMatrix A = basis.mass() + 1e-3 * basis.stiffness();
    Eigen::MatrixXd B;
    symmetric_multiply(basis.mass(), m.mesh.vertices, B);
    it = systems.emplace(size, std::make_pair(std::move(A), std::move(B))).first;
  }
  const ScopedBlasThreads blas(int(state.range(1)));
  CholmodSolver solver;
  solver.set_matrix(it->second.first);  // symbolic analysis outside the timed loop
  Eigen::MatrixXd X;
  for (auto _ : state) {
    solver.set_matrix(it->second.first);
    solver.solve(it->second.second, X);
  }
  state.counters["unknowns"] = double(it->second.first.rows());
  state.counters["blas_threads"] = double(blas_threads());
  state.counters["auto"] =
      double(auto_blas_threads(int(std::thread::hardware_concurrency()), it->second.first.rows()));
}

void blas_thread_args(benchmark::internal::Benchmark* b) {
  const int cores = int(std::thread::hardware_concurrency());
  for (int size : {0, 1})
    for (int t = 1; t <= cores; t *= 2) b->Args({size, t});
}
BENCHMARK(BM_CholmodBlasThreads)
    ->Apply(blas_thread_args)
    ->ArgNames({"size", "blas"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace mcf
