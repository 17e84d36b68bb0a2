// The phases of the two fastest steps against their floors (docs/benchmarks.md "Floors"): each
// benchmark times one phase and reports, as counters, the bytes it must move and the flops it must
// do by the model of solvers/phase_floor.h, computed from the sizes of the very matrices it works
// on, and the rates achieved (bytes_per_second, flops_per_second). reports/summarize_micro.py
// reads them beside BM_StreamTriad at the same thread count (benchmarks/micro_bandwidth.cpp).
//
// Hat basis with its surface hierarchy, two V(2,2)-cycles a step (the fastest hat step):
//   BM_Floor_HatUpdate/threads:T/matrices:M    update of M (1: cMCF) or of M and K (2)
//   BM_Floor_HatSetMatrix/threads:T/by_term:B  set_matrix_sum(M, δ, K) with a new M each call,
//                                               Galerkin by the sum (0) or by term (1)
//   BM_Floor_HatGalerkin/threads:T/below:d     the Galerkin product onto the level d + 1 below
//                                               the finest, alone
//   BM_Floor_HatGalerkinPetsc/below:d/algorithm:a  the same product by PETSc (values only, on
//                                               its pattern; one process, one thread), where the
//                                               build has PETSc, by its algorithm a: 0 "default"
//                                               (scalable), 1 "rap", 2 "hypre" (the label says):
//                                               a yardstick written by others
//   BM_Floor_HatKernel/threads:T/kernel:k/below:d  one kernel on the level d below the finest:
//                                               0 sweep, 1 residual, 2 restriction, 3 prolongation
//   BM_Floor_HatCoarsestSolve/threads:T        the direct solve on the coarsest level
//   BM_Floor_HatCycle/threads:T                one V(2,2)-cycle (MultigridSolver::precondition)
//   BM_Floor_HatEvaluate/threads:T             evaluate_vertices (a permuted copy)
// Tracked octree basis, one W(5,5)-cycle a step:
//   BM_Floor_TrackedUpdate, BM_Floor_TrackedSetMatrix, BM_Floor_TrackedCycle,
//   BM_Floor_TrackedEvaluate (threads:T); BM_Floor_TrackedGalerkin and
//   BM_Floor_TrackedGalerkinPetsc as the hat basis's, on the octree's levels
//
// Mesh: $MCFBENCH_FLOOR_MESH (default sphere:vertices=40000, a run of about a minute; the issue's
// size: cgal:armadillo@faces=832000), octree depth $MCFBENCH_FLOOR_DEPTH (default 7; 9 for the
// armadillo). Levels a mesh lacks are reported as skipped (error "no such level"). T is 1 and 2,
// or every count of $MCFBENCH_THREADS (benchmarks/thread_counts.h; benchmarks/many_core.sh).

#include "bases/hat_basis.h"
#include "bases/tracked_octree_basis.h"
#include "benchmarks/thread_counts.h"
#include "datasets/mesh_spec.h"
#include "solvers/csc_view.h"
#include "solvers/galerkin.h"
#include "solvers/multigrid.h"
#include "solvers/petsc_galerkin.h"
#include "solvers/petsc_runtime.h"
#include "solvers/phase_floor.h"
#include "solvers/symmetric_multiply.h"

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <cstdlib>
#include <memory>
#include <string>

namespace mcf {
namespace {

constexpr double kDt = 1e-3;

// Flops per element of the formulas the bases evaluate (counted from their code): the hat mass
// needs a face's area (two edges, a cross product, a norm: about 24), its stiffness three corner
// cotangents (about 90); the tracked octree per cubature point re-evaluates 8 trilinear values and
// gradients, dX (8 x 2 x 3 multiply-adds), g, √|g| and g⁻¹, and the upper halves of two 8 x 8
// blocks (about 560).
constexpr double kHatMassFlopsPerFace = 24;
constexpr double kHatStiffnessFlopsPerFace = 90;
constexpr double kTrackedFlopsPerPoint = 560;

std::string env_or(const char* name, const char* fallback) {
  const char* v = std::getenv(name);
  return v ? v : fallback;
}

const MeshSource& floor_mesh() {
  static const MeshSource m =
      load_mesh_spec(env_or("MCFBENCH_FLOOR_MESH", "sphere:vertices=40000"));
  return m;
}

/// The phase's counters: its floor (bytes, flops), the rates achieved, the thread count.
void report(benchmark::State& state, const PhaseCost& c, int threads) {
  using benchmark::Counter;
  state.counters["bytes"] = c.bytes;
  state.counters["flops"] = c.flops;
  state.counters["bytes_per_second"] = Counter(c.bytes, Counter::kIsIterationInvariantRate);
  state.counters["flops_per_second"] = Counter(c.flops, Counter::kIsIterationInvariantRate);
  state.counters["threads"] = threads;
}

/// A benchmark of one argument, the thread count: 1 and 2, or every count of $MCFBENCH_THREADS
/// (benchmarks/thread_counts.h).
void per_thread_count(benchmark::internal::Benchmark* b) {
  b->ArgName("threads")->Unit(benchmark::kMillisecond)->UseRealTime();
  for (const std::int64_t t : bench_thread_counts({1, 2})) b->Arg(t);
}

/// The thread count of range(0), held by `limit` for the benchmark's lifetime.
int set_threads(benchmark::State& state, std::unique_ptr<tbb::global_control>& limit) {
  const int t = int(state.range(0));
  limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                std::size_t(t));
  return t;
}

/// The Galerkin product onto level l (from l + 1) by the floor model.
PhaseCost galerkin_floor(const SparseMatrix& A, const SparseMatrix& P, const SparseMatrix& C) {
  return galerkin_cost(sparse_size(A), sparse_size(P), sparse_size(C), galerkin_flops(A, P, C));
}

/// One visit of level l in a cycle with `smooth` sweeps before and after: sweeps, residual,
/// restriction and prolongation (to and from level l - 1); on level 0 the direct solve.
PhaseCost visit_floor(const MultigridSolver& mg, const std::vector<SparseMatrix>& P, int l,
                      int smooth, int columns) {
  if (l == 0)
    return factor_solve_cost(mg.level_matrix(0).rows(), mg.coarsest_factor_nonzeros(), columns);
  const SparseSize A = sparse_size(mg.level_matrix(l));
  SparseSize S = A;
  S.index_bytes = 0;  // the entry's bytes, offset and value together
  S.value_bytes = mg.level_sweep_entry_bytes(l);
  PhaseCost c = (2.0 * smooth) * sweep_cost(S, mg.level_sweep_entries(l), columns);
  c += residual_cost(A, columns);
  c += restriction_cost(sparse_size(P[std::size_t(l) - 1]), columns);
  c += prolongation_cost(sparse_size(P[std::size_t(l) - 1]), columns);
  return c;
}

/// One cycle: every level's visits (counted by the solver, level_work) times its visit's floor.
PhaseCost cycle_floor(MultigridSolver& mg, const std::vector<SparseMatrix>& P, int smooth,
                      int columns) {
  Eigen::MatrixXd r = Eigen::MatrixXd::Ones(mg.level_matrix(mg.levels() - 1).rows(), 3), z;
  mg.reset_level_work();
  mg.precondition(r, z);
  PhaseCost c;
  const std::vector<MultigridLevelWork> work = mg.level_work();
  for (int l = 0; l < mg.levels(); ++l)
    c += double(work[std::size_t(l)].visits) * visit_floor(mg, P, l, smooth, columns);
  mg.reset_level_work();
  return c;
}

/// The step's set_matrix: the finest sum, then per coarse level the Galerkin product of the sum
/// (by_term false) or of the mass alone plus the level's sum (by_term: cMCF's K is kept).
PhaseCost set_matrix_floor(const MultigridSolver& mg, const std::vector<SparseMatrix>& P,
                           bool by_term) {
  const int top = mg.levels() - 1;
  PhaseCost c = matrix_sum_cost(mg.level_matrix(top).nonZeros());
  for (int l = top - 1; l >= 0; --l) {
    const SparseMatrix C = mg.level_matrix(l);
    c += galerkin_floor(mg.level_matrix(l + 1), P[std::size_t(l)], C);
    if (by_term) c += matrix_sum_cost(C.nonZeros());
  }
  return c;
}

/// One cycle of a fixture's solver (a cycle from zero: MultigridSolver::precondition) against
/// the sum of its levels' visits.
template <class Fixture>
void time_cycle(benchmark::State& state) {
  std::unique_ptr<tbb::global_control> limit;
  const int threads = set_threads(state, limit);
  Fixture& f = Fixture::get();
  Eigen::MatrixXd r, z;
  symmetric_multiply(f.basis->mass(), f.x, r);
  for (auto _ : state) {
    f.mg->precondition(r, z);
    benchmark::DoNotOptimize(z.data());
  }
  report(state, cycle_floor(*f.mg, f.P(), Fixture::smooth, 4), threads);
  state.counters["levels"] = f.mg->levels();
}

/// A fixture's evaluate_vertices against its floor (Fixture::evaluate_floor).
template <class Fixture>
void time_evaluate(benchmark::State& state) {
  std::unique_ptr<tbb::global_control> limit;
  const int threads = set_threads(state, limit);
  Fixture& f = Fixture::get();
  for (auto _ : state) {
    Positions v = f.basis->evaluate_vertices(f.x);
    benchmark::DoNotOptimize(v.data());
  }
  report(state, f.evaluate_floor(), threads);
}

// ---- the hat basis ---------------------------------------------------------------------------

struct HatFloor {
  std::unique_ptr<HatBasis> basis;
  Coefficients x;
  SparseMatrix mass[2];  // the mass and another one on its pattern: a new M every call
  std::unique_ptr<MultigridSolver> mg;
  static constexpr int smooth = 2;

  static HatFloor& get() {
    static HatFloor f = [] {
      HatFloor h;
      h.basis = std::make_unique<HatBasis>(floor_mesh().mesh, MassKind::consistent,
                                           SurfaceHierarchyOptions{});
      h.x = h.basis->initial_coefficients();
      h.mass[0] = h.basis->mass();
      h.mass[1] = h.mass[0];
      h.mass[1].coeffs() *= 1.0 + 1e-9;
      MultigridOptions o;
      o.cycle = MultigridCycle::V;
      o.pre_smooth = o.post_smooth = smooth;
      h.mg = std::make_unique<MultigridSolver>(o);
      h.mg->set_matrix_sum(1.0, h.mass[0], kDt, h.basis->stiffness(), h.view());
      return h;
    }();
    return f;
  }
  // With a pattern key, as a flow's ReducedSystem hands the basis's fixed pattern to the solver
  // (no comparison of the pattern per call).
  const std::uint64_t key = new_pattern_key();
  HierarchyView view() const { return {basis->prolongations(), basis->colours(), key}; }
  const std::vector<SparseMatrix>& P() const { return *basis->prolongations(); }
  /// A permuted copy of the coefficients.
  PhaseCost evaluate_floor() const { return copy_cost(x.rows(), 3); }
};

void BM_Floor_HatUpdate(benchmark::State& state) {
  std::unique_ptr<tbb::global_control> limit;
  const int threads = set_threads(state, limit);
  HatFloor& f = HatFloor::get();
  const bool stiffness = state.range(1) == 2;
  for (auto _ : state) {
    f.basis->update(f.x, true, stiffness);
    benchmark::DoNotOptimize(f.basis->mass().valuePtr());
  }
  const TriangleMesh& m = floor_mesh().mesh;
  report(
      state,
      assembly_cost(m.num_faces(), m.num_vertices(), f.basis->mass().nonZeros(), stiffness ? 2 : 1,
                    kHatMassFlopsPerFace + (stiffness ? kHatStiffnessFlopsPerFace : 0)),
      threads);
}
BENCHMARK(BM_Floor_HatUpdate)
    ->ArgNames({"threads", "matrices"})
    ->ArgsProduct({bench_thread_counts({1, 2}), {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_Floor_HatSetMatrix(benchmark::State& state) {
  std::unique_ptr<tbb::global_control> limit;
  const int threads = set_threads(state, limit);
  HatFloor& f = HatFloor::get();
  MultigridOptions o = f.mg->options();
  o.galerkin_by_term = state.range(1) == 1;
  MultigridSolver mg(o);
  // Two calls first: the second lays out the Galerkin plans (MultigridSolver), which every later
  // call of a flow on this pattern uses.
  mg.set_matrix_sum(1.0, f.mass[0], kDt, f.basis->stiffness(), f.view());
  mg.set_matrix_sum(1.0, f.mass[1], kDt, f.basis->stiffness(), f.view());
  int call = 0;
  for (auto _ : state)
    mg.set_matrix_sum(1.0, f.mass[++call % 2], kDt, f.basis->stiffness(), f.view());
  report(state, set_matrix_floor(mg, f.P(), o.galerkin_by_term), threads);
  state.counters["levels"] = mg.levels();
}
BENCHMARK(BM_Floor_HatSetMatrix)
    ->ArgNames({"threads", "by_term"})
    ->ArgsProduct({bench_thread_counts({1, 2}), {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/// The Galerkin product onto the level range(1) + 1 below the finest of Fixture's hierarchy, at
/// range(0) threads, as the solver computes it: through the product's plan unless range(2)
/// (`dense`; galerkin.h).
template <class Fixture>
void time_galerkin(benchmark::State& state) {
  std::unique_ptr<tbb::global_control> limit;
  const int threads = set_threads(state, limit);
  Fixture& f = Fixture::get();
  const int l = f.mg->levels() - 2 - int(state.range(1));  // the coarse level computed
  if (l < 0) {
    state.SkipWithError("no such level");
    return;
  }
  const SparseMatrix A = f.mg->level_matrix(l + 1);
  const SparseMatrix& P = f.P()[std::size_t(l)];
  // Sorted row indices (galerkin_values' pattern): Eigen's transpose sorts them.
  SparseMatrix C = SparseMatrix(SparseMatrix(f.mg->level_matrix(l).transpose()).transpose());
  const std::vector<int> transpose_pos = multigrid_detail::transpose_positions(C);
  multigrid_detail::Spa spa;
  const bool dense = state.range(2) != 0;
  const multigrid_detail::GalerkinPlan plan =
      dense ? multigrid_detail::GalerkinPlan{}
            : multigrid_detail::galerkin_plan(multigrid_detail::Csc(A), P, C, {});
  for (auto _ : state) {
    multigrid_detail::galerkin_values(multigrid_detail::Csc(A), P, C, C.valuePtr(), transpose_pos,
                                      {}, spa, &plan);
    benchmark::DoNotOptimize(C.valuePtr());
  }
  report(state, galerkin_floor(A, P, C), threads);
  state.counters["coarse_rows"] = double(C.rows());
  state.counters["plan_bytes"] = double(plan.bytes());
}

/// The same product by PETSc (PetscGalerkin), onto the level range(0) + 1 below the finest, by
/// the algorithm range(1): 0 "default", 1 "rap", 2 "hypre".
template <class Fixture>
void time_galerkin_petsc(benchmark::State& state) {
  if (!petsc_available()) {
    state.SkipWithError("built without PETSc");
    return;
  }
  Fixture& f = Fixture::get();
  const int l = f.mg->levels() - 2 - int(state.range(0));
  if (l < 0) {
    state.SkipWithError("no such level");
    return;
  }
  static const char* const algorithms[] = {"default", "rap", "hypre"};
  const char* algorithm = algorithms[state.range(1)];
  const SparseMatrix A = f.mg->level_matrix(l + 1);
  const SparseMatrix& P = f.P()[std::size_t(l)];
  PetscGalerkin product(A, P, algorithm);
  // A yardstick that computes something else measures nothing: its product must be the solver's.
  const SparseMatrix C = f.mg->level_matrix(l);
  const SparseMatrix difference = product.product() - C;
  if (difference.nonZeros() > 0 &&
      difference.coeffs().cwiseAbs().maxCoeff() > 1e-12 * C.coeffs().cwiseAbs().maxCoeff()) {
    state.SkipWithError("PETSc's product differs from the solver's");
    return;
  }
  for (auto _ : state) product.multiply();
  report(state, galerkin_floor(A, P, C), 1);
  state.SetLabel(algorithm);
}

void BM_Floor_HatGalerkin(benchmark::State& state) {
  time_galerkin<HatFloor>(state);
}
BENCHMARK(BM_Floor_HatGalerkin)
    ->ArgNames({"threads", "below", "dense"})
    ->ArgsProduct({bench_thread_counts({1, 2}), {0, 1, 2, 3}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_Floor_HatGalerkinPetsc(benchmark::State& state) {
  time_galerkin_petsc<HatFloor>(state);
}
BENCHMARK(BM_Floor_HatGalerkinPetsc)
    ->ArgNames({"below", "algorithm"})
    ->ArgsProduct({{0, 1, 2, 3}, {0, 1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_Floor_HatKernel(benchmark::State& state) {
  std::unique_ptr<tbb::global_control> limit;
  const int threads = set_threads(state, limit);
  HatFloor& f = HatFloor::get();
  MultigridSolver& mg = *f.mg;
  const int l = mg.levels() - 1 - int(state.range(2));
  const int kernel = int(state.range(1));
  if (l < 1) {
    state.SkipWithError("no such level");
    return;
  }
  const MultigridKernel kinds[] = {MultigridKernel::forward_sweep, MultigridKernel::residual,
                                   MultigridKernel::restriction, MultigridKernel::prolongation};
  constexpr int columns = 4;  // x, y, z and the zero column of the interleaved block
  for (auto _ : state) mg.run_kernel(kinds[kernel], l, 3);
  const SparseSize A = sparse_size(mg.level_matrix(l));
  const SparseSize P = sparse_size(f.P()[std::size_t(l) - 1]);
  PhaseCost c;
  if (kernel == 0) {
    SparseSize S = A;
    S.index_bytes = 0;
    S.value_bytes = mg.level_sweep_entry_bytes(l);
    c = sweep_cost(S, mg.level_sweep_entries(l), columns);
  } else if (kernel == 1) {
    c = residual_cost(A, columns);
  } else if (kernel == 2) {
    c = restriction_cost(P, columns);
  } else {
    c = prolongation_cost(P, columns);
  }
  report(state, c, threads);
  state.counters["rows"] = double(A.rows);
  state.SetLabel(kernel == 0   ? "sweep"
                 : kernel == 1 ? "residual"
                 : kernel == 2 ? "restriction"
                               : "prolongation");
}
BENCHMARK(BM_Floor_HatKernel)
    ->ArgNames({"threads", "kernel", "below"})
    ->ArgsProduct({bench_thread_counts({1, 2}), {0, 1, 2, 3}, {0, 1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_Floor_HatCoarsestSolve(benchmark::State& state) {
  std::unique_ptr<tbb::global_control> limit;
  const int threads = set_threads(state, limit);
  HatFloor& f = HatFloor::get();
  for (auto _ : state) f.mg->run_kernel(MultigridKernel::coarsest_solve, 0, 3);
  report(state,
         factor_solve_cost(f.mg->level_matrix(0).rows(), f.mg->coarsest_factor_nonzeros(), 3),
         threads);
}
BENCHMARK(BM_Floor_HatCoarsestSolve)->Apply(per_thread_count);

void BM_Floor_HatCycle(benchmark::State& state) {
  time_cycle<HatFloor>(state);
}
BENCHMARK(BM_Floor_HatCycle)->Apply(per_thread_count);

void BM_Floor_HatEvaluate(benchmark::State& state) {
  time_evaluate<HatFloor>(state);
}
BENCHMARK(BM_Floor_HatEvaluate)->Apply(per_thread_count);

// ---- the tracked octree basis ----------------------------------------------------------------

struct TrackedFloor {
  std::unique_ptr<TrackedOctreeBasis> basis;
  Coefficients x;
  std::unique_ptr<MultigridSolver> mg;
  static constexpr int smooth = 5;

  static TrackedFloor& get() {
    static TrackedFloor f = [] {
      TrackedFloor t;
      OctreeOptions o;
      o.depth = std::atoi(env_or("MCFBENCH_FLOOR_DEPTH", "7").c_str());
      t.basis = std::make_unique<TrackedOctreeBasis>(floor_mesh().mesh, o);
      t.x = t.basis->initial_coefficients();
      t.basis->update(t.x, true, true);
      MultigridOptions m;
      m.cycle = MultigridCycle::W;
      m.pre_smooth = m.post_smooth = smooth;
      t.mg = std::make_unique<MultigridSolver>(m);
      // Twice: the second call lays out the Galerkin plans, as in a flow's second step.
      for (int call = 0; call < 2; ++call)
        t.mg->set_matrix_sum(1.0, t.basis->mass(), kDt, t.basis->stiffness(), t.view());
      return t;
    }();
    return f;
  }
  // With a pattern key, as a flow's ReducedSystem hands the basis's fixed pattern to the solver
  // (no comparison of the pattern per call).
  const std::uint64_t key = new_pattern_key();
  HierarchyView view() const { return {basis->prolongations(), basis->colours(), key}; }
  const std::vector<SparseMatrix>& P() const { return *basis->prolongations(); }
  /// Each original vertex: the 8 trilinear weights of its cell's corners (VertexStencils).
  PhaseCost evaluate_floor() const {
    return stencil_cost(floor_mesh().mesh.num_vertices(), 8, x.rows(), 3);
  }
};

void BM_Floor_TrackedUpdate(benchmark::State& state) {
  std::unique_ptr<tbb::global_control> limit;
  const int threads = set_threads(state, limit);
  TrackedFloor& f = TrackedFloor::get();
  for (auto _ : state) {
    f.basis->update(f.x, true, true);
    benchmark::DoNotOptimize(f.basis->mass().valuePtr());
  }
  report(state,
         integration_cost(double(f.basis->preprocessed_bytes()), f.x.rows(),
                          f.basis->mass().nonZeros(), 2, f.basis->stats().cubature_points,
                          kTrackedFlopsPerPoint),
         threads);
  state.counters["cubature_points"] = double(f.basis->stats().cubature_points);
}

void BM_Floor_TrackedSetMatrix(benchmark::State& state) {
  std::unique_ptr<tbb::global_control> limit;
  const int threads = set_threads(state, limit);
  TrackedFloor& f = TrackedFloor::get();
  for (auto _ : state)
    f.mg->set_matrix_sum(1.0, f.basis->mass(), kDt, f.basis->stiffness(), f.view());
  report(state, set_matrix_floor(*f.mg, f.P(), false), threads);
}

void BM_Floor_TrackedGalerkin(benchmark::State& state) {
  time_galerkin<TrackedFloor>(state);
}
void BM_Floor_TrackedGalerkinPetsc(benchmark::State& state) {
  time_galerkin_petsc<TrackedFloor>(state);
}

void BM_Floor_TrackedCycle(benchmark::State& state) {
  time_cycle<TrackedFloor>(state);
}
void BM_Floor_TrackedEvaluate(benchmark::State& state) {
  time_evaluate<TrackedFloor>(state);
}

BENCHMARK(BM_Floor_TrackedUpdate)->Apply(per_thread_count);
BENCHMARK(BM_Floor_TrackedSetMatrix)->Apply(per_thread_count);
BENCHMARK(BM_Floor_TrackedGalerkin)
    ->ArgNames({"threads", "below", "dense"})
    ->ArgsProduct({bench_thread_counts({1, 2}), {0, 1, 2}, {0}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_Floor_TrackedGalerkinPetsc)
    ->ArgNames({"below", "algorithm"})
    ->ArgsProduct({{0, 1, 2}, {0, 1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_Floor_TrackedCycle)->Apply(per_thread_count);
BENCHMARK(BM_Floor_TrackedEvaluate)->Apply(per_thread_count);

}  // namespace
}  // namespace mcf
