#include "flows/flow.h"

#include "config/config_reader.h"
#include "config/flow_registry.h"
#include "config/registry.h"
#include "config/solver_registry.h"
#include "core/parallel.h"
#include "datasets/face_order.h"
#include "datasets/validate.h"
#include "flows/cylinder_reference.h"
#include "flows/planted_slowdown.h"
#include "flows/sphere_reference.h"
#include "solvers/blas_threads.h"
#include "solvers/symmetric_multiply.h"
#include "steps/integrator.h"
#include "steps/predicted_start.h"
#include "steps/reduced_system.h"
#include "steps/stabilization.h"

#include <tbb/global_control.h>
#include <tbb/info.h>
#include <Eigen/Geometry>

#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <string>

namespace mcf {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

int severity(SolveStatus s) {
  switch (s) {
    case SolveStatus::converged:
      return 0;
    case SolveStatus::max_iterations:
      return 1;
    default:
      return 2;
  }
}

/// What one step's solves did, for the step's record in result.json.
struct StepTally {
  double update_seconds = 0, solve_seconds = 0;
  double planted_seconds = 0;  ///< added by $MCFBENCH_PLANTED_SLOWDOWN (flows/planted_slowdown.h)
  int solves = 0, iterations = 0;
  double contraction = -1;  ///< the worst multigrid contraction of the step's solves (-1: none)
  /// Solves that needed more than their cycles (solvers/multigrid_fallback.h), the cycles added
  /// to reach the residual bound, and CG's iterations after them.
  int fallbacks = 0, extra_cycles = 0, fallback_iterations = 0;
  int direct_solves = 0;  ///< of those, the ones a factorization finished
  SolveReport worst;
  // Every solve's residuals, in order (Taylor-2 and Neumann-2 solve twice a step).
  std::vector<std::vector<double>> residuals_per_solve;
  // Per solve, per right-hand side (PETSc): iterations, true residual, the KSP's reason.
  nlohmann::json columns_per_solve = nlohmann::json::array();
  // Per solve (PETSc): what it did with its preconditioner (new | refreshed | kept).
  std::vector<std::string> preconditioner_setups;
};

// The StepContext of a flow: which operators are re-assembled (the flow's row: MCF both, cMCF
// mass only, heat neither after the first step), the reduced solve, and per-step timing.
class FlowStepContext final : public StepContext {
 public:
  /// With a stabilization weight every solve is one for the increment over its held values, with
  /// the basis's normal-gradient term added (steps/stabilization.h).
  FlowStepContext(Basis& basis, LinearSolver& solver, const FlowRow& flow, double dt,
                  bool iterative, std::optional<double> stabilization_weight = std::nullopt)
      : basis_(basis),
        solver_(solver),
        system_(std::make_unique<ReducedSystem>(basis, solver)),
        flow_(flow),
        dt_(dt),
        iterative_(iterative) {
    // A weight of 0 adds nothing: the plain solve, as on the paper's system.
    if (stabilization_weight && *stabilization_weight > 0.0)
      stabilized_.emplace(*stabilization_weight);
  }

  double dt() const override { return dt_; }
  const Coefficients& current() const override { return *x_; }
  const Coefficients* previous() const override { return x_prev_; }

  void evaluate_operators(const Coefficients& X) override {
    const auto t0 = Clock::now();
    const bool first = !assembled_;
    basis_.update(X, !flow_.keeps_mass || first, !flow_.keeps_stiffness || first);
    tally_.planted_seconds += plant_slowdown(PlantedPhase::update, t0);  // 0 unless planted
    assembled_ = true;
    tally_.update_seconds += seconds_since(t0);
  }
  // M and K are symmetric: a parallel, thread-count independent gather instead of Eigen's serial
  // scatter (solvers/symmetric_multiply.h).
  Coefficients apply_mass(const Coefficients& X) const override {
    return symmetric_multiply(basis_.mass(), X);
  }
  Coefficients apply_stiffness(const Coefficients& X) const override {
    return symmetric_multiply(basis_.stiffness(), X);
  }

  Coefficients solve(double a, double b, const Coefficients& R, const Coefficients& fixed,
                     const Coefficients& warm) override {
    const auto t0 = Clock::now();
    Coefficients Y;
    if (stabilized_) {
      Y = stabilized_->solve(*system_, basis_, a, b, R, fixed, warm);
    } else if (iterative_ && warm != fixed) {
      // The integrator's prediction, taken as far as it fits (steps/predicted_start.h).
      const SparseView M = basis_.mass(), K = basis_.stiffness();
      predicted_start(MatrixSum(a, M, b, K), R, fixed, warm, start_);
      start_.increment += fixed;  // the start itself
      solver_.set_start_fit(start_.theta);
      Y = system_->solve(a, b, R, fixed, start_.increment);
    } else {
      Y = system_->solve(a, b, R, fixed, warm);
    }
    StepTally& t = tally_;
    t.solve_seconds += seconds_since(t0);
    const SolveReport& r = system_->report();
    ++t.solves;
    t.iterations += r.iterations;
    t.residuals_per_solve.push_back(r.residuals);
    t.contraction = std::max(t.contraction, r.contraction);
    if (r.extra_cycles > 0 || r.fallback_iterations > 0 || r.direct_fallback) {
      ++t.fallbacks;
      t.extra_cycles += r.extra_cycles;
      t.fallback_iterations += r.fallback_iterations;
      if (r.direct_fallback) ++t.direct_solves;
    }
    if (!r.columns.empty()) {
      nlohmann::json columns = nlohmann::json::array();
      for (const ColumnReport& c : r.columns)
        columns.push_back({{"iterations", c.iterations},
                           {"relative_residual", c.relative_residual},
                           {"reason", c.reason}});
      t.columns_per_solve.push_back(std::move(columns));
    }
    if (!r.preconditioner_setup.empty()) t.preconditioner_setups.push_back(r.preconditioner_setup);
    if (severity(r.status) >= severity(t.worst.status)) t.worst = r;
    return Y;
  }

  // Per-step bookkeeping.
  void begin_step(const Coefficients& x, const Coefficients* prev) {
    x_ = &x;
    x_prev_ = prev;
    tally_ = StepTally{};
  }
  void rebuilt() {
    // A rebuilt basis has new functions: forget the reduction and assemble afresh.
    system_ = std::make_unique<ReducedSystem>(basis_, solver_);
    assembled_ = false;
  }
  void add_update_seconds(double s) { tally_.update_seconds += s; }
  void add_planted_seconds(double s) { tally_.planted_seconds += s; }
  /// ρ of the last stabilized solve (0 without stabilization).
  double stabilization_rho() const { return stabilized_ ? stabilized_->rho() : 0.0; }
  /// The current step's solves so far.
  const StepTally& tally() const { return tally_; }
  std::size_t fixed() const { return system_->num_fixed(); }

 private:
  Basis& basis_;
  LinearSolver& solver_;
  std::unique_ptr<ReducedSystem> system_;
  const FlowRow& flow_;
  double dt_;
  StepTally tally_;
  bool iterative_ = false;  ///< the solver starts from the warm start (multigrid, PCG)
  std::optional<StabilizedSolve> stabilized_;
  PredictedStart start_;  ///< the predicted start's buffers, reused from step to step
  // The caller's iterates, which outlive the step: read in place, not copied.
  const Coefficients* x_ = nullptr;
  const Coefficients* x_prev_ = nullptr;
  bool assembled_ = false;
};

nlohmann::json stats_json(const BasisStats& s) {
  nlohmann::json j = {{"dimension", s.dimension},
                      {"split_triangles", s.split_triangles},
                      {"cubature_points", s.cubature_points},
                      {"levels", s.levels},
                      {"bytes_per_cubature_point", s.bytes_per_cubature_point},
                      {"setup_seconds", s.setup_seconds}};
  if (s.cube_side > 0) j["cube"] = {{"origin", s.cube_origin}, {"side", s.cube_side}};
  return j;
}

// Row-chunked passes over a step's positions (n x 3, column-major: a chunk is three runs), in
// parallel; the chunks depend on n alone, so the sum below is the same for any thread count.
constexpr Eigen::Index kRowChunk = 16384;

bool all_finite(const Eigen::MatrixX3d& V) {
  return sum_over_chunks<Eigen::Index>(V.rows(), kRowChunk, [&](Eigen::Index r0, Eigen::Index r1) {
           return Eigen::Index(!V.middleRows(r0, r1 - r0).allFinite());
         }) == 0;
}

/// ||A - B|| (Frobenius), summed by fixed chunks.
double difference_norm(const Eigen::MatrixX3d& A, const Eigen::MatrixX3d& B) {
  return std::sqrt(
      sum_over_chunks<double>(A.rows(), kRowChunk, [&](Eigen::Index r0, Eigen::Index r1) {
        return (A.middleRows(r0, r1 - r0) - B.middleRows(r0, r1 - r0)).squaredNorm();
      }));
}

}  // namespace

nlohmann::json mesh_json(const MeshSource& source) {
  const MeshReport& rep = source.report;
  return {{"spec", source.spec},
          {"vertices", rep.vertices},
          {"faces", rep.faces},
          {"boundary_loops", rep.boundary_loops},
          {"genus", rep.genus},
          {"components", rep.connected_components},
          {"unreferenced_vertices", rep.unreferenced_vertices},
          {"area", rep.area},
          {"analytic", source.analytic},
          {"reoriented_faces", rep.reoriented_faces},
          {"repaired_faces", rep.repaired_faces},
          {"degenerate_faces", rep.degenerate_faces}};
}

namespace {

/// x -> (x - centroid) * scale, row by row (in parallel over row chunks).
void apply(const Normalization& n, Coefficients& x) {
  parallel_for_chunks<Eigen::Index>(x.rows(), kRowChunk,
                                    [&](Eigen::Index, Eigen::Index r0, Eigen::Index r1) {
                                      auto rows = x.middleRows(r0, r1 - r0);
                                      rows = (rows.rowwise() - n.centroid) * n.scale;
                                    });
}

/// One flow from its set-up to its last step: the basis, solver and integrator it sets up, the
/// iterates, the stop rules and what result.json records of each step. run_flow drives it.
class FlowRun {
 public:
  /// Set-up: the (normalised) mesh, basis, solver and integrator; result["system"] and
  /// result["solver_name"]. Throws a ConfigError for a solver that cannot take the basis.
  FlowRun(const FlowConfig& config, const MeshSource& source, nlohmann::json& result);

  const Positions& vertices() const { return V_; }
  /// Makes step `step`; false when a stop rule ends the flow there (result["stop"] says why).
  bool advance(int step);
  /// result["stop"] (if no rule stopped the flow) and result["steps"]; the final mesh.
  TriangleMesh finish();

 private:
  void begin_step(int step);
  nlohmann::json solver_record(int step, double t) const;
  std::optional<std::string> stop_rule(const Positions& V_new, const Coefficients& x_new,
                                       SurfaceMoments& moments, nlohmann::json& record) const;
  void stop(int step, Clock::time_point step_start, const std::string& reason,
            nlohmann::json& record);
  void record_references(const Positions& V_new, double t, nlohmann::json& record);

  const FlowConfig& config_;
  nlohmann::json& result_;
  TriangleMesh mesh_;
  // mesh_'s faces by smallest vertex (datasets/face_order.h): the stop rule's pass over the
  // surface after every step reads its vertices nearly in order.
  Triangles moment_faces_;
  std::unique_ptr<Basis> basis_;
  std::unique_ptr<LinearSolver> solver_;
  std::unique_ptr<Integrator> integrator_;
  double build_seconds_ = 0;  // a rebuilt basis: its step 1's update
  std::unique_ptr<FlowStepContext> ctx_;
  bool stabilized_ = false;                ///< the basis's system carries the stabilization
  bool keeps_previous_for_start_ = false;  ///< X_{n-1} for the solver's start (or prediction)
  Positions V_;
  Coefficients x_, x_prev_;
  bool has_prev_ = false;
  double area0_ = 0, previous_area_ = 0;
  std::optional<SphereReference> sphere_;
  std::optional<CylinderReference> cylinder_;
  nlohmann::json steps_ = nlohmann::json::array();
};

FlowRun::FlowRun(const FlowConfig& config, const MeshSource& source, nlohmann::json& result)
    : config_(config), result_(result), mesh_(source.mesh) {
  const Triangles& F = mesh_.faces;
  if (config.normalize_area) apply(unit_area_normalization(mesh_.vertices, F), mesh_.vertices);
  moment_faces_ = faces_by_smallest_vertex(F, mesh_.num_vertices());

  // The solver first: it may refuse its configuration (PETSc's options) before the basis is
  // built.
  solver_ = make_solver(config.solver);
  const auto setup_start = Clock::now();
  basis_ = make_basis(config, mesh_, source.analytic);
  build_seconds_ = seconds_since(setup_start);
  // A solver that takes only small systems (the dense reference) would refuse this one at its
  // first factorization: say so now, as the configuration error it is, rather than stop the
  // flow at step 1 as if it had turned singular.
  if (const Eigen::Index free =
          basis_->dimension() - Eigen::Index(basis_->locked_functions().size());
      free > solver_->max_dimension())
    throw ConfigError(source.spec + ": solver: \"" + config.solver.name + "\" factorizes at most " +
                      std::to_string(solver_->max_dimension()) + " functions and this basis has " +
                      std::to_string(free) +
                      " free ones; use \"cholmod\", \"pcg\" or \"multigrid\"");
  integrator_ = make_integrator(config.integrator, config.extrapolate);
  result["system"] = stats_json(basis_->stats());
  result["system"]["setup_seconds"]["total"] = seconds_since(setup_start);
  const Eigen::Index free_functions =
      basis_->dimension() - Eigen::Index(basis_->locked_functions().size());
  result["system"]["free_functions"] = free_functions;
  if (free_functions == 0)
    // A single triangle, a quad, a planar patch: every vertex (hat) or every function whose
    // support meets the boundary (octree) is held, and the boundary does not move. The flow
    // completes with the mesh as it is (ReducedSystem asks no solver), whatever the solver.
    result["notes"].push_back("nothing free to move: all " + std::to_string(basis_->dimension()) +
                              " functions of the " + config.basis +
                              " basis are held by the mesh's boundary, which the flow keeps "
                              "fixed, so the mesh stays as it is");
  result["solver_name"] = solver_->name();

  const BasisRow& basis = basis_row(config.basis);
  const std::optional<double> stabilization =
      basis.stabilization ? basis.stabilization(config) : std::nullopt;
  stabilized_ = stabilization.has_value();
  // The start is the stabilized solve's prediction too (StabilizedSolve::solve,
  // steps/stabilization.h), so a direct solver needs X_{n-1} then as well.
  const bool iterative = solver_row(config.solver.name).iterative;
  keeps_previous_for_start_ = stabilized_ || iterative;
  const FlowRow& flow = flow_row(config.flow);
  ctx_ = std::make_unique<FlowStepContext>(*basis_, *solver_, flow, config.dt, iterative,
                                           stabilization);
  V_ = mesh_.vertices;
  x_ = basis_->initial_coefficients();
  area0_ = surface_area(mesh_);
  previous_area_ = area0_;
  if (source.sphere_radius && !config.normalize_area)
    // On a sphere K is scale-invariant, so only a kept mass (heat flow) changes the law.
    sphere_.emplace(*source.sphere_radius, flow.keeps_mass);
  if (source.cylinder_radius && !config.normalize_area)
    cylinder_.emplace(*source.cylinder_radius, flow.keeps_mass, flow.keeps_stiffness, V_);
}

void FlowRun::begin_step(int step) {
  if (!basis_->rebuilds_every_step()) {
    ctx_->begin_step(x_, has_prev_ ? &x_prev_ : nullptr);
    return;
  }
  // Step 1 solves on the system the set-up built on X_0, so that build is its update: every
  // step's update is then one build (a step 1 recorded as ~0 made Table 1's rebuilt mean 20%
  // low over 5 steps, 33% over the quick run's 3), and X_0 is not built twice.
  const auto t0 = Clock::now();
  double planted = 0;
  if (step > 1) {
    basis_->rebuild(V_);
    ctx_->rebuilt();
    planted = plant_slowdown(PlantedPhase::update, t0);  // a rebuild is this basis's update
  }
  x_ = basis_->initial_coefficients();
  has_prev_ = false;
  ctx_->begin_step(x_, nullptr);
  ctx_->add_update_seconds(step > 1 ? seconds_since(t0) : build_seconds_);
  ctx_->add_planted_seconds(planted);
}

nlohmann::json FlowRun::solver_record(int step, double t) const {
  const StepTally& tally = ctx_->tally();
  const SolveReport& worst = tally.worst;
  nlohmann::json record = {{"step", step}, {"t", t}};
  record["solver"] = {
      {"iterations", tally.iterations},
      {"solves", tally.solves},
      {"residuals", tally.residuals_per_solve.empty() ? std::vector<double>{}
                                                      : tally.residuals_per_solve.back()},
      {"relative_residual", worst.relative_residual},
      {"status", to_string(worst.status)}};
  if (tally.solves > 1) record["solver"]["residuals_per_solve"] = tally.residuals_per_solve;
  if (tally.contraction >= 0) record["solver"]["contraction"] = tally.contraction;
  if (tally.fallbacks > 0)
    record["solver"]["fallback"] = {{"solves", tally.fallbacks},
                                    {"extra_cycles", tally.extra_cycles},
                                    {"iterations", tally.fallback_iterations},
                                    {"direct_solves", tally.direct_solves}};
  if (!tally.columns_per_solve.empty()) record["solver"]["rhs_per_solve"] = tally.columns_per_solve;
  if (!tally.preconditioner_setups.empty())
    record["solver"]["preconditioner_setup"] = tally.preconditioner_setups;
  // What the solver noted on a matrix it accepted (a semi-definite coarsest level, serial
  // Gauss-Seidel on a level), or why it failed.
  if (!worst.message.empty()) record["solver"]["message"] = worst.message;
  if (stabilized_) record["solver"]["stabilization_rho"] = ctx_->stabilization_rho();
  if (ctx_->fixed()) record["fixed_functions"] = ctx_->fixed();
  if (basis_->rebuilds_every_step()) {
    record["dimension"] = basis_->dimension();
    record["split_triangles"] = basis_->stats().split_triangles;
    record["setup_seconds"] = basis_->stats().setup_seconds;
  }
  return record;
}

std::optional<std::string> FlowRun::stop_rule(const Positions& V_new, const Coefficients& x_new,
                                              SurfaceMoments& moments,
                                              nlohmann::json& record) const {
  if (!all_finite(V_new) || !all_finite(x_new)) return "non-finite vertex positions";
  moments = surface_moments(V_new, moment_faces_);
  const double area = moments.area;
  if (!(area > 1e-12 * area0_)) {
    record["area"] = area;
    return "collapsed area (" + std::to_string(area) + ")";
  }
  if (area > 1.05 * previous_area_) {
    // MCF, cMCF and heat flow never increase the area; a step that grows it by more than 5%
    // is an unstable (explicit) step, not a flow.
    record["area"] = area;
    return "diverged: the area grew by " +
           std::to_string(int(std::lround(100 * (area / previous_area_ - 1)))) +
           "% in one step (unstable time step)";
  }
  return std::nullopt;
}

void FlowRun::stop(int step, Clock::time_point step_start, const std::string& reason,
                   nlohmann::json& record) {
  // A stopping step is recorded with its seconds too (every step has them: the result.json
  // contract), then the flow stops.
  record["seconds"] = {{"update", ctx_->tally().update_seconds},
                       {"solve", ctx_->tally().solve_seconds},
                       {"total", seconds_since(step_start)}};
  steps_.push_back(record);
  result_["status"] = "singular";
  result_["stop"] = {{"step", step}, {"reason", reason}};
}

void FlowRun::record_references(const Positions& V_new, double t, nlohmann::json& record) {
  if (cylinder_) {
    cylinder_->advance(config_.dt);
    record["cylinder"] = {{"ring_radius", cylinder_->ring_radius(V_new)},
                          {"radius_semi_implicit", cylinder_->discrete},
                          {"radius_continuous", cylinder_->continuous(t)},
                          {"ring_vertices", cylinder_->ring.size()}};
  }
  if (sphere_) {
    sphere_->advance(config_.dt);
    const RadialError d = radial_error(V_new, sphere_->discrete);
    const RadialError c = radial_error(V_new, sphere_->continuous(t));
    record["radial_error"] = {{"rms", d.rms},
                              {"max", d.max},
                              {"rms_continuous", c.rms},
                              {"max_continuous", c.max},
                              {"mean_radius", V_new.rowwise().norm().mean()},
                              {"radius_semi_implicit", sphere_->discrete},
                              {"radius_continuous", sphere_->continuous(t)}};
  }
}

bool FlowRun::advance(int step) {
  const auto step_start = Clock::now();
  const double t = step * config_.dt;
  begin_step(step);
  Coefficients x_new = integrator_->step(*ctx_);
  nlohmann::json record = solver_record(step, t);
  const SolveReport& worst = ctx_->tally().worst;
  if (!worst.ok()) {
    stop(step, step_start,
         std::string("solver: ") + to_string(worst.status) +
             (worst.message.empty() ? "" : " (" + worst.message + ")"),
         record);
    return false;
  }

  const auto eval_start = Clock::now();
  Positions V_new = basis_->evaluate_vertices(x_new);
  SurfaceMoments moments;
  if (const std::optional<std::string> reason = stop_rule(V_new, x_new, moments, record)) {
    stop(step, step_start, *reason, record);
    return false;
  }
  const double area = moments.area;
  if (config_.normalize_area) {
    const Normalization n = unit_area_normalization(moments);
    apply(n, V_new);
    apply(n, x_new);
    apply(n, x_);  // becomes X_{n-1}: same frame as X_n for two-step schemes
    basis_->reframe(n.centroid, n.scale);  // with refine_input, the flowed midpoints follow
  }
  const double step_difference = difference_norm(V_new, V_);
  previous_area_ = config_.normalize_area ? 1.0 : area;
  const double evaluate_seconds = seconds_since(eval_start);

  record["area"] = area;
  record["step_difference"] = step_difference;
  record_references(V_new, t, record);
  // X_{n-1}: for two-step schemes, and for the extrapolated start 2 X_n - X_{n-1} of a position
  // solve, which an iterative solver starts from and a stabilized solve predicts with.
  if (integrator_->uses_previous() || keeps_previous_for_start_) {
    x_prev_ = std::move(x_);
    has_prev_ = true;
  }
  x_ = std::move(x_new);  // for a one-step scheme this frees X_{n-1}
  V_ = std::move(V_new);
  ctx_->add_planted_seconds(plant_slowdown(PlantedPhase::step, step_start));  // 0 unless planted
  record["seconds"] = {{"update", ctx_->tally().update_seconds},
                       {"solve", ctx_->tally().solve_seconds},
                       {"evaluate", evaluate_seconds},
                       {"total", seconds_since(step_start)}};
  // A planted run says how long it waited on purpose, and in which phase's time that lies.
  if (planted_slowdown() > 0) record["seconds"]["planted"] = ctx_->tally().planted_seconds;
  steps_.push_back(std::move(record));
  return true;
}

TriangleMesh FlowRun::finish() {
  if (!result_.contains("stop"))
    result_["stop"] = {{"step", int(steps_.size())}, {"reason", "completed"}};
  result_["steps"] = std::move(steps_);
  // At the end: some settings are known only after the solves (PETSc's storage per rank).
  for (const auto& [key, text] : solver_->settings()) result_["solver_settings"][key] = text;
  return TriangleMesh{V_, mesh_.faces};
}

}  // namespace

Normalization unit_area_normalization(const SurfaceMoments& s) {
  Normalization n;
  if (s.area > 0) {
    n.centroid = s.weighted_centroid / s.area;
    n.scale = 1.0 / std::sqrt(s.area);
  }
  return n;
}

Normalization unit_area_normalization(const Positions& V, const Triangles& F) {
  return unit_area_normalization(surface_moments(V, F));
}

FlowOutcome run_flow(const FlowConfig& config, const MeshSource& source,
                     const FlowObserver& observer) {
  const int threads = config.threads > 0 ? config.threads : tbb::info::default_concurrency();
  tbb::global_control parallelism(tbb::global_control::max_allowed_parallelism,
                                  std::size_t(threads));
  // OpenBLAS keeps its own pool: capped at what TBB may run for the whole flow. Under that cap
  // CHOLMOD chooses its own count (solver.blas_threads, solvers/cholmod_solver.h).
  const ScopedBlasThreads blas_cap(runnable_threads(config.threads));

  validate_flow_mesh(config, source.report, source.spec);
  FlowOutcome out;
  out.result["schema"] = 1;
  out.result["status"] = "ok";
  out.result["config"] = to_json(config);
  out.result["mesh"] = mesh_json(source);
  if (!source.notes.empty()) out.result["mesh"]["notes"] = source.notes;
  FlowRun flow(config, source, out.result);
  // Hands step `step` to the observer; false when the observer ends the flow there.
  const auto observed = [&](int step) {
    if (observer.on_step) observer.on_step(step, step * config.dt, flow.vertices());
    if (!observer.stop || !observer.stop(step)) return true;
    out.result["stop"] = {{"step", step}, {"reason", "stopped by the caller"}};
    return false;
  };
  if (observed(0))
    for (int step = 1; step <= config.steps; ++step)
      if (!flow.advance(step) || !observed(step)) break;
  out.final_mesh = flow.finish();
  return out;
}

}  // namespace mcf
