#include "harness/flow_folder.h"

#include "config/registry.h"
#include "config/solver_registry.h"
#include "distributed/comm.h"
#include "distributed/distributed_flow.h"
#include "solvers/petsc_runtime.h"

#include "config/config_reader.h"
#include "config/flow_config.h"
#include "core/atomic_file.h"
#include "datasets/mesh_io.h"
#include "datasets/mesh_spec.h"
#include "flows/flow.h"
#include "harness/experiment_config.h"
#include "harness/flow_plan.h"
#include "harness/memory_budget.h"
#include "harness/progress.h"
#include "harness/result_record.h"
#include "harness/stop_signals.h"

#include <cstdio>
#include <filesystem>
#include <optional>
#include <set>
#include <stdexcept>

namespace mcf {
namespace {

namespace fs = std::filesystem;

/// Hidden (reports' globs and `collect` skip it), and removed by the next flow into OUT when a
/// killed run left it.
constexpr const char* kStagingFolder = ".mcfbench-staging";

bool is_frame_file(const fs::path& p) {
  const std::string stem = p.stem().string();
  return p.extension() == ".ply" && stem.rfind("frame_", 0) == 0 && stem.size() > 6 &&
         stem.find_first_not_of("0123456789", 6) == std::string::npos;
}

FlowConfig flow_config_of(const FlowRequest& request) {
  nlohmann::json j = nlohmann::json::object();
  std::string source = "command line";
  if (!request.config_file.empty()) {
    j = read_config_file(request.config_file);
    source = request.config_file + " (+ command line)";
  }
  for (const auto& [path, value] : request.settings) set_json_path(j, path, value);
  return flow_config_from_json(j, source);
}

/// A stop request (SIGINT, SIGTERM) seen after step `step`.
struct FlowInterrupted {
  int signal;
  int step;
};

/// Runs the flow with its progress on stderr and its frames (every config.save_every steps)
/// written into `staging`, listed in `frames`. After every step (and before the first) a stop
/// request throws FlowInterrupted, before that step's frame is written.
FlowOutcome run_staged(const FlowConfig& config, const MeshSource& mesh, const fs::path& staging,
                       double line_seconds, std::set<std::string>& frames) {
  Progress progress("step", config.steps, line_seconds);
  FlowObserver observer;
  observer.on_step = [&](int step, double, const Positions& V) {
    if (const int signal = StopSignals::received()) {
      progress.clear();
      throw FlowInterrupted{signal, step};
    }
    progress.update(step);
    if (config.save_every > 0 && step % config.save_every == 0) {
      char name[32];
      std::snprintf(name, sizeof name, "frame_%05d.ply", step);
      write_mesh((staging / name).string(), TriangleMesh{V, mesh.mesh.faces}, true,
                 FaceCheck::trusted);
      frames.insert(name);
    }
  };
  FlowOutcome outcome = run_flow(config, mesh, observer);
  progress.finish();
  return outcome;
}

/// Moves the staged files into `out`: removals and renames only, which need no space on the disk,
/// so a full disk has failed the run before the earlier run was touched. The earlier run's result
/// goes first, so from here until the new one is in place OUT holds no result at all rather than
/// one beside frames that are not its own; then the earlier run's frames that this run does not
/// replace, then this run's files move in (rename: each appears whole), result.json last.
void publish(const fs::path& out, const fs::path& staging, const std::set<std::string>& frames) {
  fs::remove(out / "result.json");
  for (const auto& entry : fs::directory_iterator(out))
    if (entry.is_regular_file() && is_frame_file(entry.path()) &&
        !frames.count(entry.path().filename().string()))
      fs::remove(entry.path());
  for (const std::string& name : frames) fs::rename(staging / name, out / name);
  fs::rename(staging / "final.ply", out / "final.ply");
  fs::rename(staging / "result.json", out / "result.json");
  sync_to_disk(out);  // the renames (each file's data was synced when it was written)
  fs::remove_all(staging);
}

/// Creates OUT's staging folder (and OUT where it is missing); `created` says whether OUT was.
fs::path make_staging(const fs::path& out, bool& created) {
  created = !fs::exists(out);
  const fs::path staging = out / kStagingFolder;
  std::error_code ec;
  fs::remove_all(staging, ec);  // a killed run's
  if (!ec) fs::create_directories(staging, ec);
  if (ec) {
    const std::string why = ec.message();
    if (created) fs::remove_all(out, ec);
    throw std::runtime_error(staging.string() + ": cannot create the staging folder: " + why);
  }
  return staging;
}

/// A rank's share of a flow's memory estimate: the mesh's, the basis's and the solver's parts
/// divided over the ranks, plus on rank 0 the mesh as read and what it keeps for the output
/// (its vertices and faces, 48 bytes a vertex of a closed mesh).
MemoryEstimate rank_share(MemoryEstimate e, int ranks) {
  e.mesh_bytes = e.mesh_bytes / ranks + 48.0 * e.vertices;
  e.basis_bytes /= ranks;
  e.solver_bytes /= ranks;
  return e;
}

/// `mcfbench flow` under mpirun -n P: rank 0 checks the memory, reads the mesh and owns the
/// output folder; every rank runs its share of the flow. A failure before the flow (a missing
/// file, a mesh the flow refuses, memory) is rank 0's to report: the other ranks exit with it
/// silently (dist::RankFailure).
int run_distributed_into_folder(const FlowPlan& plan, const FlowRequest& request) {
  const FlowConfig& config = plan.config;
  // PETSc's options checked by a trial solve on every rank, before anything is read or written
  // (solvers/petsc_solver.h): the same error on every rank, said once (tools/main.cpp).
  if (config.solver.name == "petsc") make_solver(config.solver);
  const int me = dist::rank(), P = dist::ranks();
  MeshSource mesh;
  MemoryBudget budget;
  MemoryEstimate memory;
  double line_seconds = 0;
  fs::path out(request.out), staging;
  bool created = false;
  std::exception_ptr failure;
  std::string message;
  if (me == 0) {
    try {
      budget = memory_budget(request.max_memory);
      estimate_flow(plan, budget);
      mesh = load_flow_mesh(plan);
      for (const std::string& note : mesh.notes)
        std::fprintf(stderr, "mcfbench flow: %s: %s\n", config.mesh.c_str(), note.c_str());
      validate_flow_mesh(config, mesh.report, plan.what);
      memory = rank_share(estimate_flow_memory(config, mesh_sizes(config, mesh.mesh, mesh.analytic),
                                               resident_memory_bytes()),
                          P);
      check_memory(memory, budget, config, plan.what);
      line_seconds = progress_line_seconds();
      staging = make_staging(out, created);
    } catch (const std::exception& e) {
      failure = std::current_exception();
      message = e.what();
    }
  }
  if (!dist::broadcast_message(message).empty()) {
    if (failure) std::rethrow_exception(failure);
    throw dist::RankFailure("rank 0 could not start the flow");
  }
  std::set<std::string> frames;
  FlowOutcome outcome;
  const ResultRecorder recorder(/*peak_of_this_flow=*/false);
  const StopSignals signals;
  std::optional<Progress> progress;
  if (me == 0) progress.emplace("step", config.steps, line_seconds);
  dist::DistributedObserver observer;
  observer.wants_vertices = [&](int step) {
    return config.save_every > 0 && step % config.save_every == 0;
  };
  observer.on_step = [&](int step, double, const Positions* V) {
    if (const int signal = StopSignals::received()) {
      progress->clear();
      throw FlowInterrupted{signal, step};
    }
    progress->update(step);
    if (V) {
      char name[32];
      std::snprintf(name, sizeof name, "frame_%05d.ply", step);
      write_mesh((staging / name).string(), TriangleMesh{*V, mesh.mesh.faces}, true,
                 FaceCheck::trusted);
      frames.insert(name);
    }
  };
  std::error_code ec;
  try {
    outcome = dist::run_distributed_flow(config, me == 0 ? &mesh : nullptr, observer);
    if (me != 0) return 0;
    progress->finish();
    nlohmann::json estimate = memory.to_json();
    estimate["ranks"] = P;
    estimate["scope"] = "rank 0's share";
    recorder.complete(outcome.result, config.threads, estimate, budget);
    outcome.result["peak_memory_scope"] = "rank 0 of " + std::to_string(P);
    write_mesh((staging / "final.ply").string(), outcome.final_mesh, true, FaceCheck::trusted);
    write_file_atomic((staging / "result.json").string(), outcome.result.dump(1) + "\n");
  } catch (const FlowInterrupted& stop) {
    fs::remove_all(created ? out : staging, ec);
    std::fprintf(stderr, "mcfbench flow: stopped by %s after step %d of %d; %s\n",
                 signal_name(stop.signal).c_str(), stop.step, config.steps,
                 created ? ("nothing written (" + out.string() + " removed)").c_str()
                         : (out.string() + " holds what it held before").c_str());
    return 128 + stop.signal;
  } catch (...) {
    if (me == 0) fs::remove_all(created ? out : staging, ec);
    throw;
  }
  publish(out, staging, frames);
  const auto& stop = outcome.result["stop"];
  std::fprintf(stderr, "mcfbench flow: %s after %d steps (%s) on %d ranks; wrote %s\n",
               outcome.result["status"].get<std::string>().c_str(), stop["step"].get<int>(),
               stop["reason"].get<std::string>().c_str(), P, (out / "result.json").c_str());
  return 0;
}

}  // namespace

int run_flow_into_folder(const FlowRequest& request) {
  FlowConfig config = flow_config_of(request);
  // The ranks are part of the run's config: the launcher's count where the config leaves it
  // out, and a config that names another count than the launcher started is refused.
  if (config.mpi_ranks == 1 && launched_ranks() > 1) config.mpi_ranks = launched_ranks();
  if (config.mpi_ranks != launched_ranks())
    throw ConfigError("mpi_ranks: " + std::to_string(config.mpi_ranks) +
                      " ranks asked for, but this process is one of " +
                      std::to_string(launched_ranks()) + "; start it as mpirun -n " +
                      std::to_string(config.mpi_ranks) + " mcfbench flow ..., or as a cell of " +
                      "mcfbench run, which does");
  // Under mpirun the flow is divided across the ranks (distributed/distributed_flow.h).
  if (launched_ranks() > 1) {
    if (const std::string why = dist::distributed_refusal(config, launched_ranks()); !why.empty())
      throw ConfigError(why);
    return run_distributed_into_folder(prepare_flow(config), request);
  }
  // PETSc's options are checked (a trial solve, solvers/petsc_solver.h), and a build without
  // PETSc refuses, before anything is read or written.
  if (config.solver.name == "petsc") make_solver(config.solver);
  const MemoryBudget budget = memory_budget(request.max_memory);
  // Before the mesh is generated or read (a generator's size is known from its spec), then with
  // the mesh's own sizes before the basis is built (harness/flow_plan.h).
  const FlowPlan plan = prepare_flow(config);
  estimate_flow(plan, budget);
  // Throws naming the file: nothing written.
  const MeshSource mesh = load_flow_mesh(plan);
  for (const std::string& note : mesh.notes)
    std::fprintf(stderr, "mcfbench flow: %s: %s\n", config.mesh.c_str(), note.c_str());
  const MemoryEstimate memory = check_loaded_flow(plan, mesh, budget);
  const double line_seconds = progress_line_seconds();  // a bad MCFBENCH_PROGRESS_SECONDS too

  const fs::path out(request.out);
  // A folder this run creates is removed again if the flow throws (a set-up error such as
  // `--cube unit` on a mesh outside the unit cube, a full disk): no empty folder or partial
  // frames left.
  // In a folder that exists, only the staging folder is this run's until the flow is done.
  bool created = false;
  const fs::path staging = make_staging(out, created);
  std::error_code ec;
  std::set<std::string> frames;
  FlowOutcome outcome;
  // The process runs this one flow: its peak is the flow's (with the mesh's loading).
  const ResultRecorder recorder(/*peak_of_this_flow=*/false);
  // SIGINT and SIGTERM stop the flow after the running step, as they stop `run`: the staging
  // folder goes as on any failure, and OUT keeps what it held.
  const StopSignals signals;
  // Every file of the run is written into the staging folder first: a write that fails (a full
  // disk) leaves OUT as it was, whatever it held.
  try {
    outcome = run_staged(config, mesh, staging, line_seconds, frames);
    recorder.complete(outcome.result, config.threads, memory.to_json(), budget);
    write_mesh((staging / "final.ply").string(), outcome.final_mesh, true, FaceCheck::trusted);
    write_file_atomic((staging / "result.json").string(), outcome.result.dump(1) + "\n");
  } catch (const FlowInterrupted& stop) {
    fs::remove_all(created ? out : staging, ec);
    std::fprintf(stderr, "mcfbench flow: stopped by %s after step %d of %d; %s\n",
                 signal_name(stop.signal).c_str(), stop.step, config.steps,
                 created ? ("nothing written (" + out.string() + " removed)").c_str()
                         : (out.string() + " holds what it held before").c_str());
    return 128 + stop.signal;  // as a shell reports a process the signal ended
  } catch (...) {
    fs::remove_all(created ? out : staging, ec);
    throw;
  }
  publish(out, staging, frames);
  for (const auto& note : outcome.result.value("notes", nlohmann::json::array()))
    std::fprintf(stderr, "mcfbench flow: %s\n", note.get<std::string>().c_str());
  const auto& stop = outcome.result["stop"];
  std::fprintf(stderr, "mcfbench flow: %s after %d steps (%s); wrote %s\n",
               outcome.result["status"].get<std::string>().c_str(), stop["step"].get<int>(),
               stop["reason"].get<std::string>().c_str(), (out / "result.json").c_str());
  return 0;
}

}  // namespace mcf
