#include "distributed/distributed_flow.h"

#include "config/flow_registry.h"
#include "config/multigrid_params.h"
#include "config/solver_registry.h"
#include "core/parallel.h"
#include "distributed/comm.h"
#include "distributed/rank_mesh.h"
#include "distributed/rank_system.h"
#include "flows/sphere_reference.h"
#include "flows/surface_moments.h"
#include "solvers/blas_threads.h"
#include "steps/integrator.h"

#include <tbb/global_control.h>
#include <tbb/info.h>

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>

namespace mcf::dist {

std::string distributed_refusal(const FlowConfig& config, int ranks) {
  if (ranks <= 1) return "";
  const std::string across = " across the " + std::to_string(ranks) + " ranks mpirun started";
  if (config.basis != "hat")
    return "basis: \"" + config.basis + "\" runs in one process; only the hat basis runs" + across +
           " (the octree's functions are grid cells, which a partition of the mesh's vertices "
           "does not divide)";
  if (!runs_across_ranks(config.solver))
    return "solver.name: \"" + config.solver.name +
           (config.solver.name == "pcg"
                ? "\" with preconditioner \"" + preconditioner_name(config.solver) + "\""
                : "\"") +
           " runs in one process; \"petsc\", \"multigrid\" and \"pcg\" with the multigrid "
           "preconditioner run" +
           across;
  if (config.octree.refine_input)
    return "octree.refine_input: the refined input runs in one process; refine the mesh with "
           "@faces= in its spec instead to run it" +
           across;
  return "";
}

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// The process's peak resident memory (getrusage), in bytes.
double peak_memory_bytes() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_maxrss) * 1024.0;
}

int severity(SolveStatus s) {
  return s == SolveStatus::converged ? 0 : s == SolveStatus::max_iterations ? 1 : 2;
}

/// What one step's solves did, for the step's record.
struct Tally {
  double update_seconds = 0, solve_seconds = 0;
  int solves = 0, iterations = 0, fallbacks = 0, fallback_iterations = 0, direct_solves = 0;
  std::vector<std::vector<double>> residuals_per_solve;
  nlohmann::json columns_per_solve = nlohmann::json::array();
  SolveReport worst;
  double contraction = -1;  ///< the worst multigrid contraction of the step's solves (-1: none)
};

/// The StepContext of a rank: the integrators of steps/integrator.h run unchanged on the owned
/// rows; every operator application exchanges the ghost ring first.
class RankContext final : public StepContext {
 public:
  /// `iterative`: the solver starts from the warm start (fitted to the prediction first).
  RankContext(RankSystem& system, const FlowRow& flow, double dt, bool iterative)
      : system_(system), flow_(flow), dt_(dt), iterative_(iterative) {}
  double dt() const override { return dt_; }
  const Coefficients& current() const override { return *x_; }
  const Coefficients* previous() const override { return x_prev_; }
  void evaluate_operators(const Coefficients& X) override {
    const auto t0 = Clock::now();
    const bool first = !assembled_;
    if (!flow_.keeps_mass || !flow_.keeps_stiffness || first)
      system_.update(system_.with_ghosts(X), !flow_.keeps_mass || first,
                     !flow_.keeps_stiffness || first);
    assembled_ = true;
    tally_.update_seconds += seconds_since(t0);
  }
  Coefficients apply_mass(const Coefficients& X) const override { return system_.apply_mass(X); }
  Coefficients apply_stiffness(const Coefficients& X) const override {
    return system_.apply_stiffness(X);
  }
  Coefficients solve(double a, double b, const Coefficients& R, const Coefficients& held,
                     const Coefficients& warm) override {
    const auto t0 = Clock::now();
    Coefficients Y;
    double fit = -1;
    Coefficients start;
    if (iterative_ && warm.rows() == held.rows() && warm != held) {
      // The integrator's prediction, taken as far as it fits, as a one-process flow starts
      // (steps/predicted_start.h): F + θ (P - F), θ ∈ [0, 1] minimizing ||R - A (F + θ (P - F))||,
      // its two sums added over the ranks in a fixed order.
      const Coefficients D = warm - held;
      const Coefficients r = R - system_.apply_sum(a, b, held);
      const Coefficients AD = system_.apply_sum(a, b, D);
      const std::vector<double> sums =
          dist::ordered_sum({(r.array() * AD.array()).sum(), AD.squaredNorm()});
      fit = sums[1] > 0 && std::isfinite(sums[0] / sums[1])
                ? std::clamp(sums[0] / sums[1], 0.0, 1.0)
                : 0.0;
      start = held + fit * D;
    }
    const SolveReport r = system_.solve(a, b, R, held, fit >= 0 ? start : warm, Y, fit);
    Tally& t = tally_;
    t.solve_seconds += seconds_since(t0);
    ++t.solves;
    t.iterations += r.iterations;
    t.residuals_per_solve.push_back(r.residuals);
    t.contraction = std::max(t.contraction, r.contraction);
    if (r.fallback_iterations > 0 || r.direct_fallback) {
      ++t.fallbacks;
      t.fallback_iterations += r.fallback_iterations;
      if (r.direct_fallback) ++t.direct_solves;
    }
    nlohmann::json columns = nlohmann::json::array();
    for (const ColumnReport& c : r.columns)
      columns.push_back({{"iterations", c.iterations},
                         {"relative_residual", c.relative_residual},
                         {"reason", c.reason}});
    t.columns_per_solve.push_back(std::move(columns));
    if (severity(r.status) >= severity(t.worst.status)) t.worst = r;
    return Y;
  }
  void begin_step(const Coefficients& x, const Coefficients* prev) {
    x_ = &x;
    x_prev_ = prev;
    tally_ = Tally{};
  }
  const Tally& tally() const { return tally_; }

 private:
  RankSystem& system_;
  const FlowRow& flow_;
  double dt_;
  bool iterative_;
  Tally tally_;
  bool assembled_ = false;
  const Coefficients* x_ = nullptr;
  const Coefficients* x_prev_ = nullptr;
};

// Message tags of the output's gathers.
constexpr int kTagRows = 300;

/// The owned rows of every rank on rank 0, in the input's vertex order (empty elsewhere).
Positions gather_vertices(const RankMesh& m, const OutputMap& out, const Coefficients& owned) {
  if (m.rank != 0) {
    std::vector<double> rows(3 * std::size_t(m.owned));
    for (int i = 0; i < m.owned; ++i)
      for (int c = 0; c < 3; ++c) rows[3 * std::size_t(i) + std::size_t(c)] = owned(i, c);
    send(rows, 0, kTagRows);
    return {};
  }
  Positions V(m.global_vertices, 3);
  for (int i = 0; i < m.owned; ++i)
    V.row(Eigen::Index(out.input_of_global[std::size_t(m.first + i)])) = owned.row(i);
  for (int r = 1; r < m.ranks; ++r) {
    const std::vector<double> rows = receive_doubles(r, kTagRows);
    const std::int64_t first = m.first_of[std::size_t(r)];
    for (std::size_t i = 0; i < rows.size() / 3; ++i) {
      const auto row = Eigen::Index(out.input_of_global[std::size_t(first) + i]);
      for (int c = 0; c < 3; ++c) V(row, c) = rows[3 * i + std::size_t(c)];
    }
  }
  return V;
}

/// Area and area-weighted centroid of the surface: the ordered sum of the ranks' counted
/// triangles.
SurfaceMoments moments(const Positions& local, const Triangles& counted) {
  const SurfaceMoments mine = surface_moments(local, counted);
  const std::vector<double> sum = ordered_sum(std::vector<double>{
      mine.area, mine.weighted_centroid[0], mine.weighted_centroid[1], mine.weighted_centroid[2]});
  SurfaceMoments s;
  s.area = sum[0];
  s.weighted_centroid = Eigen::RowVector3d(sum[1], sum[2], sum[3]);
  return s;
}

void apply(const Normalization& n, Coefficients& x) {
  x = (x.rowwise() - n.centroid) * n.scale;
}

/// Per phase: the slowest rank's seconds, the mean over ranks, and their ratio.
nlohmann::json phase_json(double mine) {
  const std::vector<double> all = all_values(mine);
  const double largest = *std::max_element(all.begin(), all.end());
  const double mean = std::accumulate(all.begin(), all.end(), 0.0) / double(all.size());
  return {{"max", largest}, {"mean", mean}, {"imbalance", mean > 0 ? largest / mean : 1.0}};
}

// Rank 0's word to the others after a step.
enum Word : std::uint8_t { kGoOn = 0, kFrame = 1, kStop = 2 };

std::uint8_t broadcast_word(std::uint8_t word) {
  return broadcast_bytes(std::vector<std::uint8_t>{word})[0];
}

/// The rank system's solver options from the config's solver keys.
RankSolverOptions rank_solver_options(const SolverConfig& c) {
  const MultigridOptions cycle = multigrid_options(c);
  const StallFallbackOptions guard = stall_fallback_options(c);
  RankSolverOptions solver;
  solver.solver = c.name;
  solver.petsc_options = param_value(c, solver_option("petsc_options")).get<std::string>();
  solver.tolerance = c.tolerance;
  solver.max_iterations = c.max_iterations;
  solver.cycle = to_string(cycle.cycle);
  solver.cycles = cycle.cycles;
  solver.smooth = cycle.pre_smooth;
  solver.residual_bound = guard.residual_bound;
  solver.bound_smooth_steps = guard.bound_smooth_steps;
  solver.direct_after = guard.direct_after;
  return solver;
}

/// A step's solves as its record's "solver" object (the one-process flow's keys).
nlohmann::json solver_record(const Tally& tally) {
  const SolveReport& worst = tally.worst;
  nlohmann::json r = {
      {"iterations", tally.iterations},
      {"solves", tally.solves},
      {"residuals", tally.residuals_per_solve.empty() ? std::vector<double>{}
                                                      : tally.residuals_per_solve.back()},
      {"relative_residual", worst.relative_residual},
      {"status", to_string(worst.status)},
      {"rhs_per_solve", tally.columns_per_solve}};
  if (tally.solves > 1) r["residuals_per_solve"] = tally.residuals_per_solve;
  if (tally.fallbacks > 0)
    r["fallback"] = {{"solves", tally.fallbacks},
                     {"extra_cycles", 0},
                     {"iterations", tally.fallback_iterations},
                     {"direct_solves", tally.direct_solves}};
  if (!worst.message.empty()) r["message"] = worst.message;
  if (tally.contraction >= 0) r["contraction"] = tally.contraction;
  return r;
}

/// The owned vertices' distances from the sphere's radii at time `t` (the semi-implicit
/// recursion's and the continuous one's), reduced over the ranks: collective.
nlohmann::json radial_error(const Coefficients& x, const RankMesh& mesh,
                            const SphereReference& sphere, double t) {
  double d2 = 0, d2c = 0, dmax = 0, dmaxc = 0, radius = 0;
  const double rc = sphere.continuous(t);
  for (int i = 0; i < mesh.owned; ++i) {
    const double norm = x.row(i).norm();
    const double d = std::abs(norm - sphere.discrete), dc = std::abs(norm - rc);
    d2 += d * d;
    d2c += dc * dc;
    dmax = std::max(dmax, d);
    dmaxc = std::max(dmaxc, dc);
    radius += norm;
  }
  const std::vector<double> s = ordered_sum(std::vector<double>{d2, d2c, radius});
  const double N = double(mesh.global_vertices);
  return {{"rms", std::sqrt(s[0] / N)},
          {"max", max_over_ranks(dmax)},
          {"rms_continuous", std::sqrt(s[1] / N)},
          {"max_continuous", max_over_ranks(dmaxc)},
          {"mean_radius", s[2] / N},
          {"radius_semi_implicit", sphere.discrete},
          {"radius_continuous", rc}};
}

/// A completed step's phases into its record: the slowest rank's seconds and the imbalance
/// (collective).
void record_seconds(nlohmann::json& record, const Tally& tally, double evaluate_seconds,
                    double total) {
  const nlohmann::json u = phase_json(tally.update_seconds), s = phase_json(tally.solve_seconds),
                       e = phase_json(evaluate_seconds), w = phase_json(total);
  record["seconds"] = {
      {"update", u["max"]}, {"solve", s["max"]}, {"evaluate", e["max"]}, {"total", w["max"]}};
  record["imbalance"] = {{"update", u["imbalance"]},
                         {"solve", s["imbalance"]},
                         {"evaluate", e["imbalance"]},
                         {"total", w["imbalance"]}};
}

/// What every rank held, and `phases` (collective: every rank calls it).
nlohmann::json distribution_json(const RankMesh& mesh, const RankSystem& system,
                                 nlohmann::json phases) {
  return {{"ranks", mesh.ranks},
          {"partitioner", mesh.partitioner},
          {"owned_vertices", all_values((long long)mesh.owned)},
          {"ghost_vertices", all_values((long long)mesh.ghosts())},
          {"local_faces", all_values((long long)mesh.faces.rows())},
          {"matrix_bytes", all_values(system.matrix_bytes())},
          {"preconditioner_bytes", all_values(system.preconditioner_bytes())},
          {"peak_memory_bytes", all_values(peak_memory_bytes())},
          {"phase_seconds", std::move(phases)}};
}

/// result.json's "system" of the hat basis across ranks, with the one-process flow's keys.
nlohmann::json system_json(const RankMesh& mesh, const RankSystem& system, double setup_seconds) {
  return {{"dimension", mesh.global_vertices},
          {"free_functions", mesh.global_vertices - system.held_global()},
          {"split_triangles", mesh.global_faces},
          {"cubature_points", 0},
          {"levels", system.levels()},
          {"bytes_per_cubature_point", 0},
          {"setup_seconds", {{"total", setup_seconds}}}};
}

/// The faces whose area this rank counts (each face once over all ranks).
Triangles counted_faces(const RankMesh& mesh) {
  Triangles counted(Eigen::Index(std::count(mesh.counted.begin(), mesh.counted.end(), 1)), 3);
  for (Eigen::Index f = 0, k = 0; f < mesh.faces.rows(); ++f)
    if (mesh.counted[std::size_t(f)]) counted.row(k++) = mesh.faces.row(f);
  return counted;
}

/// The sphere's reference radii where the input is a sphere and the area is not normalised, on
/// every rank (the reference's sums are collective; only rank 0 holds `source`).
std::optional<SphereReference> sphere_reference(const FlowConfig& config, const MeshSource* source,
                                                const FlowRow& flow) {
  std::optional<SphereReference> sphere;
  if (source && source->sphere_radius && !config.normalize_area)
    sphere.emplace(*source->sphere_radius, flow.keeps_mass);
  const bool sphere_flag = broadcast_word(sphere ? 1 : 0) != 0;
  const double sphere_radius = ordered_sum(sphere ? *source->sphere_radius : 0.0);
  if (sphere_flag && !sphere) sphere.emplace(sphere_radius, flow.keeps_mass);
  return sphere;
}

/// The input's area and the previous step's, against which a step's area is judged.
struct Areas {
  double initial = 0, previous = 0;
};

/// Why the step that solved with `worst` into `x_new` ends the flow, or "" where it does not:
/// the solve failed, a position is not finite, the area collapsed or grew by over 5% (an
/// unstable step). `m`: the new surface's moments where they were computed; `record` gets the
/// area of a step that fails on it. Collective.
std::string step_failure(const SolveReport& worst, const Coefficients& x_new, RankSystem& system,
                         const Triangles& counted, const Areas& areas, SurfaceMoments& m,
                         nlohmann::json& record) {
  if (!worst.ok())
    return std::string("solver: ") + to_string(worst.status) +
           (worst.message.empty() ? "" : " (" + worst.message + ")");
  if (any_rank(!x_new.allFinite())) return "non-finite vertex positions";
  m = moments(system.with_ghosts(x_new), counted);
  if (!(m.area > 1e-12 * areas.initial)) {
    record["area"] = m.area;
    return "collapsed area (" + std::to_string(m.area) + ")";
  }
  if (m.area > 1.05 * areas.previous) {
    record["area"] = m.area;
    return "diverged: the area grew by " +
           std::to_string(int(std::lround(100 * (m.area / areas.previous - 1)))) +
           "% in one step (unstable time step)";
  }
  return "";
}

/// result.json's "solver_settings": the rank system's, and how the flow was divided.
nlohmann::json solver_settings(const RankSystem& system, int ranks) {
  nlohmann::json settings = nlohmann::json::object();
  for (const auto& [key, text] : system.settings()) settings[key] = text;
  settings["ranks"] = std::to_string(ranks);
  settings["distribution"] =
      "the flow divided: each rank its vertices, their triangles and one ring of ghosts";
  return settings;
}

}  // namespace

FlowOutcome run_distributed_flow(const FlowConfig& config, const MeshSource* source,
                                 const DistributedObserver& observer) {
  // As run_flow: TBB's workers and OpenBLAS's threads (PETSc's vector kernels call BLAS) capped
  // at the config's threads, so that a rerun splits every kernel the same way.
  const int threads = config.threads > 0 ? config.threads : tbb::info::default_concurrency();
  tbb::global_control parallelism(tbb::global_control::max_allowed_parallelism,
                                  std::size_t(threads));
  const ScopedBlasThreads blas_cap(runnable_threads(config.threads));
  const int me = rank();
  FlowOutcome out;
  // Rank 0's whole mesh, normalised as a one-process flow normalises it.
  TriangleMesh whole;
  if (me == 0) {
    whole = source->mesh;
    if (config.normalize_area)
      apply(unit_area_normalization(whole.vertices, whole.faces), whole.vertices);
  }
  const auto setup_start = Clock::now();
  OutputMap output;
  const RankMesh mesh = scatter_mesh(whole, me == 0 ? &output : nullptr);
  whole = TriangleMesh{};
  const Triangles counted = counted_faces(mesh);

  const RankSolverOptions solver = rank_solver_options(config.solver);
  const MassKind mass = config.mass == "lumped" ? MassKind::lumped : MassKind::consistent;
  RankSystem system(mesh, mass, solver);
  const double setup_seconds = seconds_since(setup_start);

  const FlowRow& flow = flow_row(config.flow);
  std::unique_ptr<Integrator> integrator = make_integrator(config.integrator, config.extrapolate);
  RankContext ctx(system, flow, config.dt, solver_row(config.solver.name).iterative);
  Coefficients x = mesh.vertices.topRows(mesh.owned), x_prev;
  bool has_prev = false;
  const double area0 = moments(mesh.vertices, counted).area;
  double previous_area = area0;
  std::optional<SphereReference> sphere = sphere_reference(config, source, flow);

  nlohmann::json steps = nlohmann::json::array();
  nlohmann::json stop;
  double update_total = 0, solve_total = 0, evaluate_total = 0, step_total = 0;

  // After step `step` (0: the input): the frame gathered where rank 0 wants it, the observer
  // called; an exception there (a stop request) ends the flow on every rank.
  const auto report_step = [&](int step) {
    std::uint8_t word = kGoOn;
    if (me == 0 && observer.wants_vertices && observer.wants_vertices(step)) word = kFrame;
    word = broadcast_word(word);
    Positions V;
    if (word == kFrame) V = gather_vertices(mesh, output, x);
    std::exception_ptr failure;
    if (me == 0 && observer.on_step) {
      try {
        observer.on_step(step, step * config.dt, word == kFrame ? &V : nullptr);
      } catch (...) {
        failure = std::current_exception();
      }
    }
    if (broadcast_word(failure ? kStop : kGoOn) == kStop) {
      if (failure) std::rethrow_exception(failure);
      throw RankFailure("the flow was stopped on rank 0");
    }
  };
  report_step(0);

  for (int step = 1; step <= config.steps; ++step) {
    const auto step_start = Clock::now();
    const double t = step * config.dt;
    ctx.begin_step(x, has_prev ? &x_prev : nullptr);
    Coefficients x_new = integrator->step(ctx);
    const Tally& tally = ctx.tally();
    nlohmann::json record = {{"step", step}, {"t", t}, {"solver", solver_record(tally)}};
    const auto eval_start = Clock::now();
    SurfaceMoments m;
    const std::string reason =
        step_failure(tally.worst, x_new, system, counted, {area0, previous_area}, m, record);
    if (!reason.empty()) {
      record["seconds"] = {{"update", tally.update_seconds},
                           {"solve", tally.solve_seconds},
                           {"total", seconds_since(step_start)}};
      steps.push_back(std::move(record));
      out.result["status"] = "singular";
      stop = {{"step", step}, {"reason", reason}};
      break;
    }
    if (config.normalize_area) {
      const Normalization n = unit_area_normalization(m);
      apply(n, x_new);
      apply(n, x);
    }
    double squared = 0;
    for (int i = 0; i < mesh.owned; ++i) squared += (x_new.row(i) - x.row(i)).squaredNorm();
    const double step_difference = std::sqrt(ordered_sum(squared));
    previous_area = config.normalize_area ? 1.0 : m.area;
    record["area"] = m.area;
    record["step_difference"] = step_difference;
    if (sphere) {
      sphere->advance(config.dt);
      record["radial_error"] = radial_error(x_new, mesh, *sphere, t);
    }
    if (integrator->uses_previous() || solver_row(config.solver.name).iterative) {
      x_prev = std::move(x);
      has_prev = true;
    }
    x = std::move(x_new);
    const double evaluate_seconds = seconds_since(eval_start);
    const double total = seconds_since(step_start);
    update_total += tally.update_seconds;
    solve_total += tally.solve_seconds;
    evaluate_total += evaluate_seconds;
    step_total += total;
    record_seconds(record, tally, evaluate_seconds, total);
    steps.push_back(std::move(record));
    report_step(step);
  }

  // The final surface and what every rank held, on rank 0.
  Positions final_vertices = gather_vertices(mesh, output, x);
  const nlohmann::json distribution = distribution_json(mesh, system,
                                                        {{"setup", phase_json(setup_seconds)},
                                                         {"update", phase_json(update_total)},
                                                         {"solve", phase_json(solve_total)},
                                                         {"evaluate", phase_json(evaluate_total)},
                                                         {"steps", phase_json(step_total)}});
  if (me != 0) return out;

  nlohmann::json& result = out.result;
  result["schema"] = 1;
  if (!result.contains("status")) result["status"] = "ok";
  result["config"] = to_json(config);
  result["mesh"] = mesh_json(*source);
  if (!source->notes.empty()) result["mesh"]["notes"] = source->notes;
  result["system"] = system_json(mesh, system, setup_seconds);
  result["solver_name"] = system.name();
  result["distribution"] = distribution;
  if (stop.is_null()) stop = {{"step", int(steps.size())}, {"reason", "completed"}};
  result["stop"] = stop;
  result["steps"] = std::move(steps);
  result["solver_settings"] = solver_settings(system, mesh.ranks);
  out.final_mesh = TriangleMesh{std::move(final_vertices), std::move(output.faces)};
  return out;
}

}  // namespace mcf::dist
