// Micro-benchmarks of the octree bases and the multigrid solver (docs/benchmarks.md).
//
// Rebuilt phases on two paper-sized meshes:
//   arm  = cgal:armadillo@faces=832000 at depth 9 (unit cube), δ = 1e-5
//   sph  = sphere:vertices=370000 at depth 8 (tight cube),     δ = 1e-3
// octree build, clipping, integration, hierarchy (prolongations + colours), one V-cycle, one
// W-cycle (5 GS sweeps, 3 right-hand sides, warm start x = c on (M + δK) x = M c), one fine SpMV
// with 3 columns, and the counter wcycle_over_spmv = (one W-cycle) / (one fine SpMV).
//
// Per-step comparisons on the armadillo at depth 9, one W-cycle, 5 GS sweeps:
//   BM_Step_Tracked/threads:T  update(x,true,true) + set_matrix_sum(M, δ, K) (pattern key:
//                              values only) + W-cycle + evaluate
//   BM_Step_Rebuilt/threads:2  rebuild(vertices) + set_matrix_sum(M, δ, K) (fresh solver: new
//                              pattern) + W-cycle + evaluate
//   BM_Step_HatCholmod/threads:2  hat update + M+δK + CHOLMOD refactorize + solve
//                              (symbolic analysis outside the loop)
//   BM_Step_HatMultigrid/threads:2/cycle:C  the hat basis with its surface hierarchy: update +
//                              set_matrix_sum (Galerkin values) + predicted start + one
//                              W(5,5)-cycle (C = 0) or two V(2,2)-cycles (C = 1) + evaluate
// Ratios: reports/summarize_micro.py turns the JSON into the tables of docs/benchmarks.md.
//
// Fixtures are large (several GB at depth 9 on 832k faces), so only one lives at a time: taking
// one frees the previous. Keep benchmarks that share a fixture next to each other.
// Mesh overrides: $MCFBENCH_OCTREE_ARM_MESH, $MCFBENCH_OCTREE_SPH_MESH, depths
// $MCFBENCH_OCTREE_ARM_DEPTH, $MCFBENCH_OCTREE_SPH_DEPTH (smaller runs, profiling).

#include "bases/clip.h"
#include "bases/hat_basis.h"
#include "bases/octree.h"
#include "bases/octree_basis.h"
#include "bases/octree_system.h"
#include "bases/tracked_octree_basis.h"
#include "benchmarks/thread_counts.h"
#include "datasets/mesh_spec.h"
#include "harness/environment.h"
#include "solvers/blas_threads.h"
#include "solvers/cholmod_solver.h"
#include "solvers/multigrid.h"
#include "solvers/symmetric_multiply.h"
#include "steps/predicted_start.h"
#include "steps/stabilization.h"

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <functional>
#include <map>
#include <memory>
#include <string>

namespace mcf {
namespace {

using Clock = std::chrono::steady_clock;

/// The four phases of a timed step (update — or rebuild —, set_matrix, solve, evaluate), summed
/// over the timed steps and reported per step with the last solve's residual and the thread count
/// (range(0)). `first` names the first phase's counter.
struct StepPhases {
  const char* first = "update_ms";
  double update = 0, set = 0, solve = 0, evaluate = 0;
  void add(Clock::time_point t0, Clock::time_point t1, Clock::time_point t2, Clock::time_point t3,
           Clock::time_point t4) {
    update += std::chrono::duration<double>(t1 - t0).count();
    set += std::chrono::duration<double>(t2 - t1).count();
    solve += std::chrono::duration<double>(t3 - t2).count();
    evaluate += std::chrono::duration<double>(t4 - t3).count();
  }
  void report(benchmark::State& state, double residual) const {
    const double n = double(state.iterations());
    state.counters[first] = 1e3 * update / n;
    state.counters["set_matrix_ms"] = 1e3 * set / n;
    state.counters["solve_ms"] = 1e3 * solve / n;
    state.counters["evaluate_ms"] = 1e3 * evaluate / n;
    state.counters["relative_residual"] = residual;
    state.counters["threads"] = double(state.range(0));
  }
};

// Warm-up: every step and cycle benchmark runs its body once untimed before the timed
// iterations. The first solve allocates the multigrid's per-level buffers (and the first CHOLMOD
// factorization its factor); on virtual machines the first use of memory the process has not had
// before is slow (the host backs the pages then), enough to distort an average of a few steps
// (docs/benchmarks.md). The steady state is what a flow of many steps sees.

struct Case {
  std::string spec;
  int depth;
  OctreeCube cube;
  double dt;
};

Case arm_case() {
  const char* s = std::getenv("MCFBENCH_OCTREE_ARM_MESH");
  const char* d = std::getenv("MCFBENCH_OCTREE_ARM_DEPTH");
  return {s ? s : "cgal:armadillo@faces=832000", d ? std::atoi(d) : 9, OctreeCube::unit, 1e-5};
}
Case sph_case() {
  const char* s = std::getenv("MCFBENCH_OCTREE_SPH_MESH");
  const char* d = std::getenv("MCFBENCH_OCTREE_SPH_DEPTH");
  return {s ? s : "sphere:vertices=370000", d ? std::atoi(d) : 8, OctreeCube::tight, 1e-3};
}

/// Meshes are small next to the octree fixtures; keep them for the whole run.
const MeshSource& mesh(const std::string& spec) {
  static std::map<std::string, MeshSource> cache;
  auto it = cache.find(spec);
  if (it == cache.end()) it = cache.emplace(spec, load_mesh_spec(spec)).first;
  return it->second;
}

OctreeOptions options(const Case& c) {
  OctreeOptions o;
  o.depth = c.depth;
  o.cube = c.cube;
  o.cubature = 3;
  return o;
}

/// One live fixture at a time: taking another frees the current one first.
struct Slot {
  std::string key;
  std::shared_ptr<void> object;
};
Slot& slot() {
  static Slot s;
  return s;
}
template <class F>
F& acquire(const std::string& key, const std::function<std::unique_ptr<F>()>& make) {
  Slot& s = slot();
  if (s.key != key || !s.object) {
    s.object.reset();  // free first: two depth-9 fixtures may not fit together
    s.key.clear();
    std::shared_ptr<F> f = make();
    s.object = f;
    s.key = key;
  }
  return *static_cast<F*>(s.object.get());
}

MultigridOptions mg_options(MultigridCycle cycle) {
  MultigridOptions o;
  o.cycle = cycle;
  o.cycles = 1;
  o.pre_smooth = 5;
  o.post_smooth = 5;
  o.tolerance = 0.0;
  return o;
}

// ---------------------------------------------------------------------------------------------
// Rebuilt phases

struct PhaseFixture {
  Case c;
  const MeshSource* source = nullptr;
  std::unique_ptr<RebuiltOctreeBasis> basis;
  SparseMatrix A;           // M + δK
  Eigen::MatrixXd C, B;     // x = c, b = M c
  double spmv_seconds = 0;  // best of several fine SpMVs with 3 columns (filled lazily)
};

PhaseFixture& phase_fixture(int which) {
  const Case c = which == 0 ? arm_case() : sph_case();
  return acquire<PhaseFixture>("phase:" + c.spec + "@" + std::to_string(c.depth), [c] {
    auto f = std::make_unique<PhaseFixture>();
    f->c = c;
    f->source = &mesh(c.spec);
    f->basis = std::make_unique<RebuiltOctreeBasis>(f->source->mesh, options(c));
    f->A = f->basis->mass() + c.dt * f->basis->stiffness();
    f->C = f->basis->initial_coefficients();
    symmetric_multiply(f->basis->mass(), f->C, f->B);
    return f;
  });
}

double best_spmv_seconds(PhaseFixture& f) {
  if (f.spmv_seconds > 0) return f.spmv_seconds;
  Eigen::MatrixXd Y(f.A.rows(), 3);
  double best = 1e300;
  for (int r = 0; r < 7; ++r) {
    const auto t0 = Clock::now();
    Y.noalias() = f.A * f.C;
    best = std::min(best, std::chrono::duration<double>(Clock::now() - t0).count());
    benchmark::DoNotOptimize(Y.data());
  }
  return f.spmv_seconds = best;
}

void label(benchmark::State& state, const PhaseFixture& f) {
  const BasisStats& s = f.basis->stats();
  state.counters["dimension"] = double(s.dimension);
  state.counters["split_triangles"] = double(s.split_triangles);
  state.counters["cubature_points"] = double(s.cubature_points);
  state.counters["levels"] = double(s.levels);
  state.counters["depth"] = double(f.c.depth);
  state.counters["vertices"] = double(f.source->mesh.num_vertices());
  state.counters["faces"] = double(f.source->mesh.num_faces());
  state.counters["nnz"] = double(f.A.nonZeros());
  state.SetLabel(f.c.spec);
}

void BM_Rebuilt_Clip(benchmark::State& state) {
  auto& f = phase_fixture(int(state.range(0)));
  const GridCube& cube = f.basis->octree().cube;
  for (auto _ : state) {
    auto pieces = clip_mesh(f.source->mesh.vertices, f.source->mesh.faces, cube);
    benchmark::DoNotOptimize(pieces.data());
  }
  label(state, f);
}

void BM_Rebuilt_Octree(benchmark::State& state) {
  auto& f = phase_fixture(int(state.range(0)));
  const GridCube& cube = f.basis->octree().cube;
  for (auto _ : state) {
    Octree o = build_octree(cube, f.basis->pieces(), f.basis->options().coarsest_depth);
    auto cells = locate_pieces(o, f.basis->pieces());
    benchmark::DoNotOptimize(cells.data());
  }
  label(state, f);
}

void BM_Rebuilt_Integrate(benchmark::State& state) {
  auto& f = phase_fixture(int(state.range(0)));
  const Octree& octree = f.basis->octree();
  std::vector<double> M, K;
  for (auto _ : state) {
    OctreeSystem sys(octree, octree.num_levels() - 1, f.basis->pieces(), f.basis->piece_cells());
    sys.assemble(cubature_rule(3), M, K);
    benchmark::DoNotOptimize(K.data());
  }
  label(state, f);
}

void BM_Rebuilt_Hierarchy(benchmark::State& state) {
  auto& f = phase_fixture(int(state.range(0)));
  for (auto _ : state) {
    auto P = build_prolongations(f.basis->octree());
    auto colours = build_colours(f.basis->octree());
    benchmark::DoNotOptimize(P.data());
    benchmark::DoNotOptimize(colours.data());
  }
  label(state, f);
}

void BM_Rebuilt_SpMV(benchmark::State& state) {
  auto& f = phase_fixture(int(state.range(0)));
  Eigen::MatrixXd Y(f.A.rows(), 3);
  for (auto _ : state) {
    Y.noalias() = f.A * f.C;
    benchmark::DoNotOptimize(Y.data());
  }
  label(state, f);
}

// range(0): mesh; range(1): 0 = V-cycle, 1 = W-cycle.
void BM_Rebuilt_Cycle(benchmark::State& state) {
  auto& f = phase_fixture(int(state.range(0)));
  const bool w = state.range(1) == 1;
  MultigridSolver solver(mg_options(w ? MultigridCycle::W : MultigridCycle::V));
  solver.set_matrix(f.A, {f.basis->prolongations(), f.basis->colours()});
  Eigen::MatrixXd X = f.C;
  solver.solve(f.B, X);  // warm-up (see "Warm-up" at the top): the solver's buffers
  solver.reset_level_work();
  double residual = 0, cycle_seconds = 0;
  for (auto _ : state) {
    state.PauseTiming();
    X = f.C;  // warm start x = c
    state.ResumeTiming();
    const auto t0 = Clock::now();
    residual = solver.solve(f.B, X).relative_residual;
    cycle_seconds += std::chrono::duration<double>(Clock::now() - t0).count();
  }
  cycle_seconds /= double(state.iterations());
  const double spmv = best_spmv_seconds(f);
  state.counters["relative_residual"] = residual;
  state.counters["spmv_ms"] = 1e3 * spmv;
  state.counters[w ? "wcycle_over_spmv" : "vcycle_over_spmv"] = cycle_seconds / spmv;
  state.counters["mg_levels"] = solver.levels();
  // Per level (0 = coarsest): visits and own milliseconds per cycle (MultigridLevelWork), so the
  // coarse levels' share of a W-cycle is read off the run rather than estimated.
  const auto work = solver.level_work();
  const double per = 1.0 / double(state.iterations());
  for (std::size_t l = 0; l < work.size(); ++l) {
    state.counters["level" + std::to_string(l) + "_visits"] = double(work[l].visits) * per;
    state.counters["level" + std::to_string(l) + "_ms"] = 1e3 * work[l].seconds * per;
  }
  state.counters["solve_ms"] =
      1e3 * cycle_seconds;  // the cycle plus copies in/out and the final residual
  label(state, f);
}

// One forward Gauss-Seidel sweep (timed as 5) on the finest level (3 right-hand sides), in fine
// SpMVs: the unit the W-cycle's cost is made of (a W-cycle is 10 fine sweeps + 1 residual + coarse
// work).
void BM_Rebuilt_Sweep(benchmark::State& state) {
  auto& f = phase_fixture(int(state.range(0)));
  MultigridSolver solver(mg_options(MultigridCycle::W));
  solver.set_matrix(f.A, {f.basis->prolongations(), f.basis->colours()});
  Eigen::MatrixXd X = f.C;
  const int fine = solver.levels() - 1;
  solver.gauss_seidel(fine, f.B, X, 1);  // warm-up (see "Warm-up" at the top): the solver's buffers
  X = f.C;
  double seconds = 0;
  for (auto _ : state) {
    const auto t0 = Clock::now();
    solver.gauss_seidel(fine, f.B, X, 5);  // 5 sweeps amortize the copy in and out
    seconds += std::chrono::duration<double>(Clock::now() - t0).count();
  }
  seconds /= 5.0 * double(state.iterations());
  state.counters["sweep_over_spmv"] = seconds / best_spmv_seconds(f);
  label(state, f);
}

void BM_Rebuilt_SetMatrix(benchmark::State& state) {
  auto& f = phase_fixture(int(state.range(0)));
  MultigridSolver solver(mg_options(MultigridCycle::W));
  solver.set_matrix(f.A, {f.basis->prolongations(), f.basis->colours()});  // symbolic once
  for (auto _ : state) solver.set_matrix(f.A, {f.basis->prolongations(), f.basis->colours()});
  state.counters["symbolic_builds"] = double(solver.symbolic_builds());
  label(state, f);
}

// Meshes: 0 = armadillo depth 9, 1 = sphere depth 8. Grouped by mesh so each fixture is built once.
void phase_args(benchmark::internal::Benchmark* b) {
  b->ArgName("mesh")->Unit(benchmark::kMillisecond)->UseRealTime();
}

#define MCF_PHASES(mesh_id)                                                                        \
  BENCHMARK(BM_Rebuilt_Octree)->Arg(mesh_id)->Apply(phase_args)->Iterations(mesh_id == 0 ? 2 : 3); \
  BENCHMARK(BM_Rebuilt_Clip)->Arg(mesh_id)->Apply(phase_args)->Iterations(mesh_id == 0 ? 2 : 3);   \
  BENCHMARK(BM_Rebuilt_Integrate)                                                                  \
      ->Arg(mesh_id)                                                                               \
      ->Apply(phase_args)                                                                          \
      ->Iterations(mesh_id == 0 ? 2 : 3);                                                          \
  BENCHMARK(BM_Rebuilt_Hierarchy)                                                                  \
      ->Arg(mesh_id)                                                                               \
      ->Apply(phase_args)                                                                          \
      ->Iterations(mesh_id == 0 ? 2 : 3);                                                          \
  BENCHMARK(BM_Rebuilt_SpMV)->Arg(mesh_id)->Apply(phase_args);                                     \
  BENCHMARK(BM_Rebuilt_SetMatrix)->Arg(mesh_id)->Apply(phase_args)->Iterations(3);                 \
  BENCHMARK(BM_Rebuilt_Sweep)->Arg(mesh_id)->Apply(phase_args)->Iterations(5);                     \
  BENCHMARK(BM_Rebuilt_Cycle)                                                                      \
      ->Args({mesh_id, 0})                                                                         \
      ->ArgNames({"mesh", "W"})                                                                    \
      ->Unit(benchmark::kMillisecond)                                                              \
      ->UseRealTime()                                                                              \
      ->Iterations(3);                                                                             \
  BENCHMARK(BM_Rebuilt_Cycle)                                                                      \
      ->Args({mesh_id, 1})                                                                         \
      ->ArgNames({"mesh", "W"})                                                                    \
      ->Unit(benchmark::kMillisecond)                                                              \
      ->UseRealTime()                                                                              \
      ->Iterations(3);

MCF_PHASES(0)
MCF_PHASES(1)

// ---------------------------------------------------------------------------------------------
// Per-step comparisons on the armadillo at depth 9.

struct TrackedFixture {
  Case c;
  const MeshSource* source = nullptr;
  std::unique_ptr<TrackedOctreeBasis> basis;
  Coefficients x;  // the step's starting coefficients (identity: every step the same work)
};

TrackedFixture& tracked_fixture() {
  const Case c = arm_case();
  return acquire<TrackedFixture>("tracked:" + c.spec + "@" + std::to_string(c.depth), [c] {
    auto f = std::make_unique<TrackedOctreeBasis>(mesh(c.spec).mesh, options(c));
    auto t = std::make_unique<TrackedFixture>();
    t->c = c;
    t->source = &mesh(c.spec);
    t->x = f->initial_coefficients();
    t->basis = std::move(f);
    return t;
  });
}

/// Runs the timed iterations and records `steal_ms`: CPU time per iteration that the hypervisor
/// gave to other guests (all vCPUs, /proc/stat's steal; -1 where unknown). A repetition much
/// slower than its siblings with a large steal_ms was the machine, not the code (a small one
/// rules out only stolen CPU time, not contention for caches and memory bandwidth).
template <class Step>
void timed_steps(benchmark::State& state, Step&& step) {
  const double before = cpu_steal_seconds();
  for (auto _ : state) step(true);
  const double steal = cpu_steal_seconds_since(before);
  state.counters["steal_ms"] = steal >= 0 ? 1e3 * steal / double(state.iterations()) : -1.0;
}

void step_counters(benchmark::State& state, const Case& c, const MeshSource& m,
                   const BasisStats& s) {
  state.counters["dimension"] = double(s.dimension);
  state.counters["split_triangles"] = double(s.split_triangles);
  state.counters["cubature_points"] = double(s.cubature_points);
  state.counters["depth"] = double(c.depth);
  state.counters["vertices"] = double(m.mesh.num_vertices());
  state.counters["faces"] = double(m.mesh.num_faces());
  state.SetLabel(c.spec);
}

// range(0): TBB threads.
void BM_Step_Tracked(benchmark::State& state) {
  auto& f = tracked_fixture();
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism,
                              std::size_t(state.range(0)));
  TrackedOctreeBasis& basis = *f.basis;
  MultigridSolver solver(mg_options(MultigridCycle::W));
  // As in a flow (ReducedSystem): the tracked pattern is fixed, so it is checked once and the
  // solver is told so through a pattern key instead of comparing it every step.
  const HierarchyView h{basis.prolongations(), basis.colours(), new_pattern_key()};
  // M + δK goes to the solver as set_matrix_sum, as ReducedSystem hands it over: the multigrid
  // writes the sum straight into its finest matrix.
  basis.update(f.x, true, true);
  solver.set_matrix_sum(1.0, basis.mass(), f.c.dt, basis.stiffness(), h);  // Galerkin pattern once
  Eigen::MatrixXd X, B;
  StepPhases phases;
  double residual = 0;
  const auto step = [&](bool timed) {
    auto t0 = Clock::now();
    basis.update(f.x, true, true);
    auto t1 = Clock::now();
    solver.set_matrix_sum(1.0, basis.mass(), f.c.dt, basis.stiffness(), h);
    auto t2 = Clock::now();
    symmetric_multiply(basis.mass(), f.x, B);
    X = f.x;  // warm start from the previous step's coefficients
    residual = solver.solve(B, X).relative_residual;
    auto t3 = Clock::now();
    Positions v = basis.evaluate_vertices(X);
    benchmark::DoNotOptimize(v.data());
    auto t4 = Clock::now();
    if (timed) phases.add(t0, t1, t2, t3, t4);
  };
  step(false);  // warm-up (see "Warm-up" at the top)
  timed_steps(state, step);
  phases.report(state, residual);
  state.counters["bytes_per_cubature_point"] = basis.stats().bytes_per_cubature_point;
  state.counters["preprocessed_bytes"] = double(basis.preprocessed_bytes());
  state.counters["setup_s"] = [&] {
    double s = 0;
    for (const auto& [k, v] : basis.stats().setup_seconds)
      if (k != "integrate_initial") s += v;
    return s;
  }();
  step_counters(state, f.c, *f.source, basis.stats());
}
BENCHMARK(BM_Step_Tracked)
    ->ArgName("threads")
    ->Apply([](benchmark::internal::Benchmark* b) {
      for (const std::int64_t t : bench_thread_counts({2, 1})) b->Arg(t);
    })
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(5);

// The stabilized tracked step (steps/stabilization.h) as a flow takes it: update, the system
// M + δK + ρS written into the solver (ρ from the traces), the start along the prediction and the
// right-hand side -δ K x + ρ S Δ̂ (steps/predicted_start.h), one cycle from Δ̂, and the
// evaluation of x + Δ. range(0): TBB threads, range(1): 0 = W-cycle, 1 = V-cycle, range(2):
// Gauss-Seidel sweeps before and after.
TrackedFixture& stabilized_fixture() {
  const Case c = arm_case();
  return acquire<TrackedFixture>("stabilized:" + c.spec + "@" + std::to_string(c.depth), [c] {
    OctreeOptions o = options(c);
    o.normal_gradient = true;
    auto f = std::make_unique<TrackedOctreeBasis>(mesh(c.spec).mesh, o);
    auto t = std::make_unique<TrackedFixture>();
    t->c = c;
    t->source = &mesh(c.spec);
    t->x = f->initial_coefficients();
    t->basis = std::move(f);
    return t;
  });
}

void BM_Step_TrackedStabilized(benchmark::State& state) {
  auto& f = stabilized_fixture();
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism,
                              std::size_t(state.range(0)));
  TrackedOctreeBasis& basis = *f.basis;
  MultigridOptions o = mg_options(state.range(1) == 0 ? MultigridCycle::W : MultigridCycle::V);
  o.pre_smooth = o.post_smooth = int(state.range(2));
  o.cycles = int(state.range(3));
  MultigridSolver solver(o);
  const HierarchyView h{basis.prolongations(), basis.colours(), new_pattern_key()};
  const double c = 0.5, dt = f.c.dt;
  const SparseView S = basis.normal_gradient();
  // The previous step: this step's increment, solved to 1e-6, taken as the last one, so that the
  // prediction is what a flow at rest in its increments has (the timed cycle's work is the same
  // whatever its start).
  basis.update(f.x, true, true);
  double rho = stabilization_rho(c, 1.0, dt, basis.mass(), basis.stiffness(), S);
  solver.set_matrix_sum(MatrixSum(1.0, basis.mass(), dt, basis.stiffness(), rho, S), h);
  Coefficients previous = f.x;
  {
    MultigridOptions exact = o;
    exact.cycles = 20;
    exact.tolerance = 1e-6;
    solver.set_options(exact);
    const PredictedStart s = predicted_start(MatrixSum(1.0, basis.mass(), dt, basis.stiffness()),
                                             symmetric_multiply(basis.mass(), f.x), f.x, f.x);
    Eigen::MatrixXd B = s.residual, X = Eigen::MatrixXd::Zero(f.x.rows(), 3);
    solver.solve(B, X);
    previous = f.x - X;
    solver.set_options(o);
  }
  const Coefficients prediction = 2.0 * f.x - previous;
  Eigen::MatrixXd X, B;
  StepPhases phases;
  double residual = 0;
  const auto step = [&](bool timed) {
    auto t0 = Clock::now();
    basis.update(f.x, true, true);
    auto t1 = Clock::now();
    rho = stabilization_rho(c, 1.0, dt, basis.mass(), basis.stiffness(), S);
    solver.set_matrix_sum(MatrixSum(1.0, basis.mass(), dt, basis.stiffness(), rho, S), h);
    auto t2 = Clock::now();
    PredictedStart s = predicted_start(MatrixSum(1.0, basis.mass(), dt, basis.stiffness()),
                                       symmetric_multiply(basis.mass(), f.x), f.x, prediction);
    s.residual.noalias() += rho * symmetric_multiply(S, s.increment);
    B = s.residual;
    X = s.increment;
    residual = solver.solve(B, X).relative_residual;
    auto t3 = Clock::now();
    Positions v = basis.evaluate_vertices(Coefficients(f.x + X));
    benchmark::DoNotOptimize(v.data());
    auto t4 = Clock::now();
    if (timed) phases.add(t0, t1, t2, t3, t4);
  };
  step(false);  // warm-up (see "Warm-up" at the top)
  timed_steps(state, step);
  phases.report(state, residual);
  state.counters["smooth"] = double(state.range(2));
  state.counters["cycles"] = double(o.cycles);
  step_counters(state, f.c, *f.source, basis.stats());
  state.SetLabel(std::to_string(o.cycles) + "x " + (state.range(1) == 0 ? "W(" : "V(") +
                 std::to_string(state.range(2)) + "," + std::to_string(state.range(2)) + ") " +
                 f.c.spec);
}
BENCHMARK(BM_Step_TrackedStabilized)
    ->ArgNames({"threads", "vcycle", "smooth", "cycles"})
    ->Args({2, 0, 5, 1})
    ->Args({2, 1, 5, 1})
    ->Args({2, 1, 3, 1})
    ->Args({2, 1, 2, 1})
    ->Args({2, 1, 2, 2})
    ->Args({2, 0, 3, 1})
    ->Args({2, 0, 2, 1})
    ->Args({1, 1, 3, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(5);

// The tracked update alone, by matrix (range(0): 1 = mass, 2 = stiffness, 3 = both), 1 thread:
// shows how the per-step update splits between the shared per-point geometry and each matrix.
void BM_Tracked_Update(benchmark::State& state) {
  auto& f = tracked_fixture();
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 1);
  const bool mass = state.range(0) & 1, stiffness = state.range(0) & 2;
  for (auto _ : state) {
    f.basis->update(f.x, mass, stiffness);
    benchmark::DoNotOptimize(f.basis->stiffness().valuePtr());
  }
  f.basis->update(f.x, true, true);  // leave both matrices current for the step benchmarks
  state.SetLabel(mass && stiffness ? "mass+stiffness" : mass ? "mass" : "stiffness");
  step_counters(state, f.c, *f.source, f.basis->stats());
}
BENCHMARK(BM_Tracked_Update)
    ->ArgName("matrices")
    ->Arg(3)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(2);

struct RebuiltStepFixture {
  Case c;
  const MeshSource* source = nullptr;
  std::unique_ptr<RebuiltOctreeBasis> basis;
};

void BM_Step_Rebuilt(benchmark::State& state) {
  const Case c = arm_case();
  auto& f =
      acquire<RebuiltStepFixture>("rebuilt-step:" + c.spec + "@" + std::to_string(c.depth), [c] {
        auto r = std::make_unique<RebuiltStepFixture>();
        r->c = c;
        r->source = &mesh(c.spec);
        r->basis = std::make_unique<RebuiltOctreeBasis>(r->source->mesh, options(c));
        return r;
      });
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism,
                              std::size_t(state.range(0)));
  RebuiltOctreeBasis& basis = *f.basis;
  const Positions& vertices = f.source->mesh.vertices;
  Eigen::MatrixXd X, B;
  StepPhases phases{"rebuild_ms"};
  double residual = 0;
  const auto step = [&](bool timed) {
    auto t0 = Clock::now();
    basis.rebuild(vertices);
    auto t1 = Clock::now();
    // A fresh solver: after a rebuild on a moved mesh the pattern is new, so the Galerkin pattern
    // must be rebuilt (reusing the solver on identical vertices would skip that).
    MultigridSolver solver(mg_options(MultigridCycle::W));
    solver.set_matrix_sum(1.0, basis.mass(), c.dt, basis.stiffness(),
                          {basis.prolongations(), basis.colours()});
    auto t2 = Clock::now();
    X = basis.initial_coefficients();
    symmetric_multiply(basis.mass(), X, B);
    residual = solver.solve(B, X).relative_residual;
    auto t3 = Clock::now();
    Positions v = basis.evaluate_vertices(X);
    benchmark::DoNotOptimize(v.data());
    auto t4 = Clock::now();
    if (timed) phases.add(t0, t1, t2, t3, t4);
  };
  step(false);  // warm-up (see "Warm-up" at the top)
  timed_steps(state, step);
  phases.report(state, residual);
  step_counters(state, c, *f.source, basis.stats());
}
BENCHMARK(BM_Step_Rebuilt)
    ->ArgName("threads")
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(2);

struct HatStepFixture {
  const MeshSource* source = nullptr;
  std::unique_ptr<HatBasis> basis;
};

void BM_Step_HatCholmod(benchmark::State& state) {
  const Case c = arm_case();
  auto& f = acquire<HatStepFixture>("hat-step:" + c.spec, [c] {
    auto h = std::make_unique<HatStepFixture>();
    h->source = &mesh(c.spec);
    h->basis = std::make_unique<HatBasis>(h->source->mesh);
    return h;
  });
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism,
                              std::size_t(state.range(0)));
  // CHOLMOD's BLAS at the same count, as a flow with `threads` runs it (solvers/blas_threads.h).
  const ScopedBlasThreads blas(int(state.range(0)));
  HatBasis& basis = *f.basis;
  const Coefficients x = f.source->mesh.vertices;
  CholmodSolver solver;
  // The key the flow's ReducedSystem passes for the basis's fixed pattern: no comparison a step.
  HierarchyView keyed;
  keyed.pattern_key = new_pattern_key();
  // Symbolic analysis outside the loop.
  solver.set_matrix_sum(1.0, basis.mass(), c.dt, basis.stiffness(), keyed);
  Eigen::MatrixXd X, B;
  double t_update = 0, t_factor = 0, t_solve = 0;
  const auto step = [&](bool timed) {
    auto t0 = Clock::now();
    basis.update(x, true, true);
    auto t1 = Clock::now();
    // M + δK as the flow hands it over (ReducedSystem): formed in CHOLMOD's lower triangle.
    solver.set_matrix_sum(1.0, basis.mass(), c.dt, basis.stiffness(), keyed);
    auto t2 = Clock::now();
    symmetric_multiply(basis.mass(), x, B);
    solver.solve(B, X);
    Positions v = basis.evaluate_vertices(X);
    benchmark::DoNotOptimize(v.data());
    auto t3 = Clock::now();
    if (!timed) return;
    t_update += std::chrono::duration<double>(t1 - t0).count();
    t_factor += std::chrono::duration<double>(t2 - t1).count();
    t_solve += std::chrono::duration<double>(t3 - t2).count();
  };
  step(false);  // warm-up (see "Warm-up" at the top)
  timed_steps(state, step);
  const double n = double(state.iterations());
  state.counters["update_ms"] = 1e3 * t_update / n;
  state.counters["factorize_ms"] = 1e3 * t_factor / n;
  state.counters["solve_ms"] = 1e3 * t_solve / n;
  state.counters["analyses"] = solver.analyses();
  state.counters["factor_nnz"] = double(solver.factor_nonzeros());
  state.counters["threads"] = double(state.range(0));
  state.counters["dimension"] = double(basis.dimension());
  state.counters["vertices"] = double(f.source->mesh.num_vertices());
  state.counters["faces"] = double(f.source->mesh.num_faces());
  state.SetLabel(c.spec);
}
BENCHMARK(BM_Step_HatCholmod)
    ->ArgName("threads")
    ->Apply([](benchmark::internal::Benchmark* b) {
      for (const std::int64_t t : bench_thread_counts({2})) b->Arg(t);
    })
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3);

void BM_Step_HatMultigrid(benchmark::State& state) {
  const Case c = arm_case();
  auto& f = acquire<HatStepFixture>("hat-multigrid-step:" + c.spec, [c] {
    auto h = std::make_unique<HatStepFixture>();
    h->source = &mesh(c.spec);
    h->basis = std::make_unique<HatBasis>(h->source->mesh, MassKind::consistent,
                                          SurfaceHierarchyOptions{});
    return h;
  });
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism,
                              std::size_t(state.range(0)));
  HatBasis& basis = *f.basis;
  MultigridOptions o;
  const bool v = state.range(1) == 1;
  o.cycle = v ? MultigridCycle::V : MultigridCycle::W;
  o.cycles = v ? 2 : 1;
  o.pre_smooth = o.post_smooth = v ? 2 : 5;
  MultigridSolver solver(o);
  HierarchyView keyed{basis.prolongations(), basis.colours(), new_pattern_key()};
  const Coefficients x = basis.initial_coefficients();
  // The Galerkin pattern outside the loop, as the flow builds it once.
  solver.set_matrix_sum(MatrixSum(1.0, basis.mass(), c.dt, basis.stiffness()), keyed);
  Eigen::MatrixXd B, X;
  double t_update = 0, t_galerkin = 0, t_solve = 0;
  const auto step = [&](bool timed) {
    auto t0 = Clock::now();
    basis.update(x, true, true);
    auto t1 = Clock::now();
    const MatrixSum sum(1.0, basis.mass(), c.dt, basis.stiffness());
    solver.set_matrix_sum(sum, keyed);
    auto t2 = Clock::now();
    symmetric_multiply(basis.mass(), x, B);
    const PredictedStart start = predicted_start(sum, B, x, x);
    X = x + start.increment;
    solver.solve(B, X);
    Positions vtx = basis.evaluate_vertices(X);
    benchmark::DoNotOptimize(vtx.data());
    auto t3 = Clock::now();
    if (!timed) return;
    t_update += std::chrono::duration<double>(t1 - t0).count();
    t_galerkin += std::chrono::duration<double>(t2 - t1).count();
    t_solve += std::chrono::duration<double>(t3 - t2).count();
  };
  step(false);  // warm-up (see "Warm-up" at the top)
  timed_steps(state, step);
  const double n = double(state.iterations());
  state.counters["update_ms"] = 1e3 * t_update / n;
  state.counters["set_matrix_ms"] = 1e3 * t_galerkin / n;
  state.counters["solve_ms"] = 1e3 * t_solve / n;
  state.counters["threads"] = double(state.range(0));
  state.counters["mg_levels"] = double(solver.levels());
  state.counters["vertices"] = double(f.source->mesh.num_vertices());
  state.counters["faces"] = double(f.source->mesh.num_faces());
  state.SetLabel(c.spec);
}
BENCHMARK(BM_Step_HatMultigrid)
    ->ArgNames({"threads", "cycle"})
    ->ArgsProduct({bench_thread_counts({2}), {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3);

/// Frees the last fixture (registered last, so it runs after every octree benchmark).
void BM_Octree_Release(benchmark::State& state) {
  for (auto _ : state) {
    slot().object.reset();
    slot().key.clear();
  }
}
BENCHMARK(BM_Octree_Release)->Iterations(1);

}  // namespace
}  // namespace mcf
