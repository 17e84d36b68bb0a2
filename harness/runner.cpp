#include "harness/runner.h"

#include "config/config_reader.h"
#include "core/atomic_file.h"
#include "datasets/mesh_io.h"
#include "flows/flow.h"
#include "harness/cell_hash.h"
#include "harness/environment.h"
#include "harness/flow_plan.h"
#include "harness/memory_budget.h"
#include "harness/metrics.h"
#include "harness/result_record.h"
#include "harness/subprocess.h"

#include <cctype>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace mcf {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string frame_name(int step) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%05d.ply", step);
  return name;
}

/// A stop request met between two steps of a cell: not a std::exception, so the cell's own
/// handler (which records a flow's failure as the cell's result) lets it through.
struct Interrupt {
  int signal;
};

/// A file of the cell (a frame, its folder) could not be written: the run's output is at fault,
/// not the cell, so it stops the run instead of becoming the cell's result.
struct OutputFailure : std::runtime_error {
  using std::runtime_error::runtime_error;
};

json read_json_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  try {
    return json::parse(in);
  } catch (const json::parse_error& e) {
    throw std::runtime_error(path + ": JSON parse error: " + e.what());
  }
}

json cell_json(const ExperimentConfig& e, const CellPlan& p) {
  return {{"index", p.cell.index},
          {"key", p.key},
          {"config_key", p.config_key},
          {"hash", p.hash},
          {"assignment", p.cell.assignment},
          {"repetition", p.cell.repetition},
          {"study", e.name},
          {"quick", e.quick},
          {"mesh_fingerprint", p.mesh_fingerprint}};
}

/// A cell with mpi_ranks > 1: `mpirun -n P` runs this binary's `mcfbench flow` on the cell's
/// config into a scratch folder under OUT, writing every step's frame where the cell needs frames
/// or per-step metrics; the frames are then handed to `observer` as the steps would have been,
/// so the cell's frames and metrics are made as for a cell run in this process. Returns the flow's
/// result.json (its peak memory: rank 0's) and final mesh. Throws std::runtime_error when mpirun
/// cannot be started or the flow fails (its own messages are on stderr).
FlowOutcome run_flow_across_ranks(const FlowConfig& config, bool needs_frames,
                                  const fs::path& scratch, const FlowObserver& observer) {
  std::error_code ec;
  fs::remove_all(scratch, ec);
  fs::create_directories(scratch, ec);
  if (ec) throw OutputFailure(scratch.string() + ": cannot create the folder: " + ec.message());
  FlowConfig child = config;
  if (needs_frames) child.save_every = 1;
  const fs::path config_file = scratch / "config.json";
  write_file_atomic(config_file.string(), to_json(child).dump(2) + "\n");
  const int ranks = config.mpi_ranks;
  std::vector<std::string> argv{"mpirun", "-n", std::to_string(ranks)};
  // Open MPI refuses more ranks than cores unless told (a 2-core machine asking for 4).
  if (unsigned(ranks) > std::thread::hardware_concurrency()) argv.push_back("--oversubscribe");
  argv.insert(argv.end(),
              {fs::read_symlink("/proc/self/exe").string(), "flow", "--config",
               config_file.string(), "--max-memory", "none", "--out", (scratch / "flow").string()});
  // The environment of this process's start: a PETSc cell run here before made MPI's singleton
  // start, whose variables would tie the new mpirun to this process.
  const ProgramResult r = run_program(argv, /*startup_environment=*/true);
  if (!r.out.empty()) std::fprintf(stderr, "%s", r.out.c_str());  // mpirun's own messages
  if (!r.ok())
    throw std::runtime_error(
        "mpirun -n " + std::to_string(ranks) + " mcfbench flow: " +
        (r.start_error.empty()
             ? "exit status " + std::to_string(r.status) + " (its messages above)"
             : "could not start mpirun (" + r.start_error + "; apt-get install openmpi-bin)"));
  FlowOutcome outcome;
  outcome.result = read_json_file((scratch / "flow" / "result.json").string());
  outcome.result["config"] = to_json(config);  // as the cell asked, without the frames it needed
  outcome.final_mesh = read_mesh((scratch / "flow" / "final.ply").string());
  // The frames are the steps the flow completed, each handed over as run_flow's observer sees it.
  const int stop = outcome.result["stop"].value("step", 0);
  for (int step = 0; needs_frames && step <= stop; ++step) {
    const fs::path frame = scratch / "flow" / frame_name(step);
    if (fs::exists(frame))
      observer.on_step(step, step * config.dt, read_mesh(frame.string()).vertices);
  }
  fs::remove_all(scratch, ec);
  return outcome;
}

json run_cell(const ExperimentConfig& e, const CellPlan& p, MeshCache& meshes, const fs::path& out,
              const MemoryBudget& budget, const std::function<void(int step)>& on_step) {
  const MetricsConfig& m = e.metrics;
  const FlowConfig& config = p.cell.flow;
  const std::set<int> frames(m.frames.begin(), m.frames.end());
  const fs::path frame_dir = out / "frames" / p.hash;
  std::vector<int> written;
  std::map<int, json> step_metrics;
  const bool per_step = m.quasi_conformal || m.sphericity;
  const ResultRecorder recorder(/*peak_of_this_flow=*/true);

  json result;
  json memory;
  try {
    const MeshSource& source = meshes.get(config);
    memory = estimate_flow_memory(config, mesh_sizes(config, source.mesh, source.analytic),
                                  resident_memory_bytes())
                 .to_json();
    if (!frames.empty() || config.save_every > 0) {
      std::error_code ec;
      fs::create_directories(frame_dir, ec);  // write_mesh does not
      if (ec)
        throw OutputFailure(frame_dir.string() + ": cannot create the folder: " + ec.message());
    }
    TriangleMesh initial;  // X_0 as the flow sees it (after area normalisation, if any)
    auto measure = [&](int step, const Positions& V) {
      json mj = json::object();
      if (m.quasi_conformal) mj["quasi_conformal"] = quasi_conformal_error(initial, V);
      if (m.sphericity) mj["sphericity"] = sphericity(V, source.mesh.faces);
      step_metrics[step] = std::move(mj);
    };
    FlowObserver observer;
    observer.on_step = [&](int step, double, const Positions& V) {
      if (step == 0) initial = TriangleMesh{V, source.mesh.faces};
      if (frames.count(step) || (config.save_every > 0 && step % config.save_every == 0)) {
        try {
          write_mesh((frame_dir / frame_name(step)).string(), TriangleMesh{V, source.mesh.faces},
                     true, FaceCheck::trusted);
        } catch (const std::exception& ex) {
          throw OutputFailure(ex.what());
        }
        written.push_back(step);
      }
      // Metrics at step 0 too (the initial sphericity is the baseline of the cMCF plots), then
      // every `every` steps and at the last step (a stopped flow's last completed step: below).
      if (per_step && (step % m.every == 0 || step == config.steps)) measure(step, V);
      if (on_step) on_step(step);  // after the step's frames and metrics: they are part of its time
    };
    FlowOutcome outcome =
        config.mpi_ranks > 1
            ? run_flow_across_ranks(config, per_step || !frames.empty() || config.save_every > 0,
                                    out / ".mpi" / p.hash, observer)
            : run_flow(config, source, observer);
    // A flow that stopped early (singular, diverged) never reached config.steps: its last
    // completed step is the one before the stop, whose state is the final mesh (the stopping
    // step is recorded but its positions are dropped, and the observer does not see it).
    // It gets metrics too, as the last step of a completed flow does.
    const int last_ok = outcome.result["stop"].value("step", 0) - 1;
    if (per_step && outcome.result["status"] == "singular" && last_ok >= 0 &&
        !step_metrics.count(last_ok))
      measure(last_ok, outcome.final_mesh.vertices);
    result = std::move(outcome.result);
    // The observer runs after the flow has recorded the step; attach the metrics by step number.
    if (step_metrics.count(0)) result["initial_metrics"] = step_metrics[0];
    for (auto& s : result["steps"]) {
      auto it = step_metrics.find(s.value("step", -1));
      if (it != step_metrics.end()) s["metrics"] = it->second;
    }
  } catch (const OutputFailure&) {
    throw;
  } catch (const std::exception& ex) {
    result = {{"schema", 1},
              {"status", "error"},
              {"error", ex.what()},
              {"stop", {{"step", 0}, {"reason", std::string("error: ") + ex.what()}}},
              {"config", p.cell.config},
              {"steps", json::array()}};
  }
  // Across ranks the flow ran in other processes: their peak (rank 0's), not this one's.
  const json child_peak = config.mpi_ranks > 1 ? result.value("peak_memory_bytes", json()) : json();
  recorder.complete(result, config.threads, memory, budget);
  if (!child_peak.is_null()) {
    result["peak_memory_bytes"] = child_peak;
    result["peak_memory_scope"] = "rank 0 of mpirun -n " + std::to_string(config.mpi_ranks);
  }
  result["cell"] = cell_json(e, p);
  result["study_config"] = e.study_config;
  if (!written.empty()) result["frames"] = {{"dir", "frames/" + p.hash}, {"steps", written}};
  return result;
}

namespace {

/// For metrics.reference: the reference cell of `cell` (same repetition preferred, then the
/// one agreeing with the cell on most assigned keys, then the lowest index); nullptr if none or
/// if the cell is a reference cell itself. A reference is a flow of the same surface: it agrees
/// with the cell on the mesh, the flow and the area normalisation unless the reference's own
/// assignment sets them (a study whose reference is excluded on some mesh has none there, rather
/// than one of another mesh).
const CellPlan* reference_for(const ExperimentConfig& e, const std::vector<CellPlan>& plans,
                              const CellPlan& cell) {
  const json& ref = e.metrics.reference;
  if (ref.is_null() || matches_assignment(cell.cell, ref)) return nullptr;
  const auto same_surface = [&](const CellPlan& p) {
    for (const char* key : {"mesh", "flow", "normalize_area"}) {
      if (ref.contains(key)) continue;
      const json* a = json_at_path(p.cell.config, key);
      const json* b = json_at_path(cell.cell.config, key);
      if (!a || !b || *a != *b) return false;
    }
    return true;
  };
  const CellPlan* best = nullptr;
  std::pair<int, int> best_score{-1, -1};
  for (const CellPlan& p : plans) {
    if (!matches_assignment(p.cell, ref) || !same_surface(p)) continue;
    int agree = 0;
    for (auto it = cell.cell.assignment.begin(); it != cell.cell.assignment.end(); ++it) {
      const json* v = json_at_path(p.cell.config, it.key());
      if (v && *v == *it) ++agree;
    }
    const std::pair<int, int> score{p.cell.repetition == cell.cell.repetition ? 1 : 0, agree};
    if (score > best_score) {  // strict: ties keep the lowest index
      best_score = score;
      best = &p;
    }
  }
  return best;
}

}  // namespace

/// Distances between this cell's frames and its reference cell's frames at the same steps.
json reference_distances(const ExperimentConfig& e, const fs::path& out, const CellPlan& cell,
                         const CellPlan& ref) {
  json list = json::array();
  for (int step : e.metrics.frames) {
    const fs::path a = out / "frames" / cell.hash / frame_name(step);
    const fs::path b = out / "frames" / ref.hash / frame_name(step);
    if (!fs::exists(a) || !fs::exists(b)) continue;
    const MeshDistance d =
        mesh_distance(read_mesh(a.string()), read_mesh(b.string()), e.metrics.distance_samples);
    list.push_back({{"step", step},
                    {"rms", d.rms},
                    {"max", d.max},
                    {"rms_forward", d.rms_forward},
                    {"max_forward", d.max_forward},
                    {"rms_backward", d.rms_backward},
                    {"max_backward", d.max_backward},
                    {"samples", d.samples}});
  }
  return list;
}

/// Adds the reference distances the shard's finished cells lack, or whose cell or reference ran
/// again now (`ran_now`, by hash). A stop request between two cells throws Interrupt. Returns how
/// many cells got their distances.
int add_reference_distances(const ExperimentConfig& e, const RunOptions& o,
                            const std::vector<CellPlan>& plans,
                            const std::set<std::string>& ran_now,
                            const std::function<int()>& stop_requested) {
  const fs::path out(o.out_dir);
  int added = 0;
  struct Pending {
    const CellPlan* cell;
    const CellPlan* reference;
    json result;  // the cell's result as read, completed below
  };
  std::vector<Pending> work;
  // Whether each reference's own flow succeeded: read once, though many cells share it.
  std::map<const CellPlan*, bool> reference_ok;
  for (const CellPlan& p : plans) {
    if (!in_shard(p.cell.index, o.shard_index, o.shard_count)) continue;
    if (const int signal = stop_requested()) throw Interrupt{signal};
    const CellPlan* ref = reference_for(e, plans, p);
    if (!ref && fs::exists(p.file)) {
      // No reference (any more): distances an earlier run recorded are not this study's.
      json result = read_json_file(p.file);
      if (result.erase("reference_distance") + result.erase("reference_cell") > 0)
        write_file_atomic(p.file, result.dump(1) + "\n");
      continue;
    }
    if (!ref || !fs::exists(p.file) || !fs::exists(ref->file)) continue;
    json result = read_json_file(p.file);
    const bool stale =
        ran_now.count(p.hash) || ran_now.count(ref->hash) || !result.contains("reference_distance");
    if (!stale || result.value("status", "") == "error") continue;
    const auto known = reference_ok.find(ref);
    const bool ok =
        known != reference_ok.end()
            ? known->second
            : (reference_ok[ref] = read_json_file(ref->file).value("status", "") != "error");
    if (!ok) continue;
    work.push_back({&p, ref, std::move(result)});
  }
  // A large reference makes each frame's distance slow: the progress says how far they are.
  for (auto& [p, ref, result] : work) {
    if (const int signal = stop_requested()) throw Interrupt{signal};
    result["reference_distance"] = reference_distances(e, out, *p, *ref);
    result["reference_cell"] = {{"index", ref->cell.index},
                                {"hash", ref->hash},
                                {"key", ref->key},
                                {"assignment", ref->cell.assignment},
                                {"repetition", ref->cell.repetition}};
    write_file_atomic(p->file, result.dump(1) + "\n");
    ++added;
    if (o.on_distance) o.on_distance(added, int(work.size()), p->cell.index);
  }
  return added;
}

}  // namespace

RunStopped::RunStopped(int signal_number, const RunSummary& run_summary, int cells_done)
    : std::runtime_error("stopped by signal " + std::to_string(signal_number)),
      signal(signal_number),
      summary(run_summary),
      done(cells_done) {}

const MeshSource& MeshCache::get(const FlowConfig& flow) {
  // The hint only words the refusal: the treatment of zero-area faces makes the mesh.
  const std::string key =
      flow.mesh + "\n" + std::to_string(static_cast<int>(mesh_load_options(flow).degenerate));
  auto it = meshes_.find(key);
  if (it == meshes_.end())
    it = meshes_.emplace(key, std::make_shared<MeshSource>(load_flow_mesh(prepare_flow(flow))))
             .first;
  return *it->second;
}

std::string code_version() {
  static const std::string v = environment_json(1).value("commit", "unknown");
  return v;
}

bool cell_finished(const std::string& file) {
  if (!fs::exists(file)) return false;
  std::ifstream in(file);
  const json r = json::parse(in, nullptr, /*allow_exceptions=*/false);
  return r.is_object() && r.contains("status") && r["status"].is_string() && r["status"] != "error";
}

bool in_shard(int index, int shard_index, int shard_count) {
  return index % shard_count == shard_index;
}

void parse_shard(const std::string& text, int& shard_index, int& shard_count) {
  const auto slash = text.find('/');
  try {
    if (slash == std::string::npos) throw std::invalid_argument("");
    size_t a = 0, b = 0;
    const int i = std::stoi(text.substr(0, slash), &a);
    const int n = std::stoi(text.substr(slash + 1), &b);
    if (a != slash || b != text.size() - slash - 1 || n < 1 || i < 0 || i >= n)
      throw std::invalid_argument("");
    shard_index = i;
    shard_count = n;
  } catch (const std::logic_error&) {
    throw std::invalid_argument("--shard: expected i/n with 0 <= i < n (e.g. 3/16), got \"" + text +
                                "\"");
  }
}

std::vector<CellPlan> plan_cells(const ExperimentConfig& e, const std::string& out_dir,
                                 MeshCache& meshes, int threads,
                                 const std::function<bool(const Cell&)>& wanted) {
  std::vector<CellPlan> plans;
  const std::string version = code_version();
  for (const Cell& c : e.cells) {
    CellPlan p;
    p.cell = c;
    if (threads >= 0) {
      p.cell.flow.threads = threads;
      p.cell.config["threads"] = threads;
    }
    if (!wanted || wanted(c)) {
      try {
        p.mesh_fingerprint = mesh_fingerprint(meshes.get(c.flow).mesh);
      } catch (const std::exception& ex) {
        throw ConfigError(e.source + " (cell " + std::to_string(c.index) + " " +
                          c.assignment.dump() + "): mesh: " + ex.what());
      }
      // Before any cell runs: a cell that cannot run on its mesh stops the whole plan.
      validate_flow_mesh(
          c.flow, meshes.get(c.flow).report,
          e.source + " (cell " + std::to_string(c.index) + " " + c.assignment.dump() + ")");
      p.key = cell_key(p.cell.config, c.repetition, p.mesh_fingerprint);
      p.config_key = cell_key(p.cell.config, -1, p.mesh_fingerprint);
      p.hash = cell_hash(p.key, version);
      p.file = (fs::path(out_dir) / (p.hash + ".json")).string();
    }
    plans.push_back(std::move(p));
  }
  return plans;
}

namespace {

/// The plan `run` writes into OUT before its first cell: the whole matrix it expanded (index,
/// repetition, assignment of every cell; the hash of the cells it named), the study config, the
/// commit and the shard, so `collect` knows which cells to expect even when a run was killed
/// before finishing any. One file per study variant, commit and shard (one writer each):
/// OUT/plans/<study>[-quick]@<commit>[.shard-<i>-of-<n>].json. Not a `*.json` file of OUT
/// itself, so nothing that reads cell results sees it.
nlohmann::json run_plan(const ExperimentConfig& e, const std::vector<CellPlan>& plans,
                        int shard_index, int shard_count) {
  json cells = json::array();
  for (const CellPlan& p : plans) {
    json c = {{"index", p.cell.index},
              {"repetition", p.cell.repetition},
              {"assignment", p.cell.assignment}};
    if (!p.hash.empty()) c["hash"] = p.hash;
    cells.push_back(std::move(c));
  }
  return {{"schema", 1},
          {"plan", "mcfbench run"},
          {"study", e.name},
          {"quick", e.quick},
          {"commit", code_version()},
          {"source", e.source},
          {"shard", std::to_string(shard_index) + "/" + std::to_string(shard_count)},
          {"cells_total", plans.size()},
          {"cells", std::move(cells)},
          {"study_config", e.study_config}};
}

}  // namespace

std::string run_plan_path(const std::string& out_dir, const ExperimentConfig& e, int shard_index,
                          int shard_count) {
  auto safe = [](std::string s) {
    for (char& ch : s)
      if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '.' && ch != '_' && ch != '-')
        ch = '_';
    return s;
  };
  std::string name = safe(e.name) + (e.quick ? "-quick" : "") + "@" + safe(code_version());
  if (shard_count > 1)
    name += ".shard-" + std::to_string(shard_index) + "-of-" + std::to_string(shard_count);
  return (fs::path(out_dir) / kPlanFolder / (name + ".json")).string();
}

std::vector<std::size_t> execution_order(const ExperimentConfig& e,
                                         const std::vector<CellPlan>& plans, int shard_index,
                                         int shard_count) {
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < plans.size(); ++i)
    if (in_shard(plans[i].cell.index, shard_index, shard_count)) order.push_back(i);
  if (!e.interleave || e.repetitions <= 1) return order;
  std::map<int, std::vector<std::size_t>> rounds;
  for (std::size_t i : order) rounds[plans[i].cell.repetition].push_back(i);
  order.clear();
  for (auto& [round, cells] : rounds) {
    // std::shuffle's and the distributions' algorithms are the library's own; the engine's
    // output is fixed by the standard, so the draw below is the same everywhere.
    std::mt19937_64 engine(std::uint64_t(e.order_seed) * 1000003u + std::uint64_t(round));
    for (std::size_t i = cells.size(); i > 1; --i) {
      const std::uint64_t limit =
          std::numeric_limits<std::uint64_t>::max() - std::numeric_limits<std::uint64_t>::max() % i;
      std::uint64_t r;
      do r = engine();
      while (r >= limit);
      std::swap(cells[i - 1], cells[std::size_t(r % i)]);
    }
    order.insert(order.end(), cells.begin(), cells.end());
  }
  return order;
}

RunSummary run_experiment(const ExperimentConfig& e, const RunOptions& o) {
  if (o.shard_count < 1 || o.shard_index < 0 || o.shard_index >= o.shard_count)
    throw std::invalid_argument("--shard: expected i/n with 0 <= i < n");
  const bool with_reference = !e.metrics.reference.is_null();
  const MemoryBudget budget = memory_budget(o.max_memory);
  auto cell_name = [&](const Cell& c) {
    return e.source + " (cell " + std::to_string(c.index) + " " + c.assignment.dump() + ")";
  };
  // A cell too large for the memory is refused from its spec's sizes before any mesh is built.
  // A spec that does not parse is left to plan_cells, which names the config and the cell.
  // With distances_only no cell runs, so none is checked.
  std::map<int, FlowPlan> flow_plans;  // by cell index
  for (const Cell& c : e.cells) {
    if (o.distances_only || !in_shard(c.index, o.shard_index, o.shard_count)) continue;
    try {
      flow_plans[c.index] = prepare_flow(c.flow, cell_name(c) + ", mesh " + c.flow.mesh);
    } catch (const std::exception&) {
      continue;
    }
    estimate_flow(flow_plans[c.index], budget);
  }
  MeshCache meshes;
  // Every mesh this shard needs is loaded (and every cell named) before anything is written,
  // so a bad mesh spec fails the run cleanly. Reference distances need the names of all cells.
  const std::vector<CellPlan> plans =
      plan_cells(e, o.out_dir, meshes, o.threads, [&](const Cell& c) {
        return with_reference || in_shard(c.index, o.shard_index, o.shard_count);
      });

  // And from its mesh's sizes once the meshes are loaded: the cells still to run.
  for (const CellPlan& p : plans)
    if (!o.distances_only && in_shard(p.cell.index, o.shard_index, o.shard_count) &&
        (o.force || !cell_finished(p.file))) {
      FlowPlan& plan = flow_plans.at(p.cell.index);
      plan.config = p.cell.flow;  // with the run's threads
      check_loaded_flow(plan, meshes.get(p.cell.flow), budget);
    }

  RunSummary s;
  s.total = int(plans.size());
  for (const auto& p : plans) s.in_shard += in_shard(p.cell.index, o.shard_index, o.shard_count);
  const fs::path out(o.out_dir);
  auto stop_requested = [&] { return o.stop_requested ? o.stop_requested() : 0; };
  if (o.distances_only) {
    for (const CellPlan& p : plans)
      if (in_shard(p.cell.index, o.shard_index, o.shard_count))
        ++(cell_finished(p.file) ? s.skipped : s.not_run);
    try {
      if (with_reference) s.distances = add_reference_distances(e, o, plans, {}, stop_requested);
    } catch (const Interrupt& stop) {
      throw RunStopped(stop.signal, s, s.skipped);
    }
    return s;
  }
  fs::create_directories(out);
  // Before the first cell: a run killed at any point leaves the list of cells it owed, which
  // `collect` checks the results against (without it an empty folder looked complete).
  write_file_atomic(run_plan_path(o.out_dir, e, o.shard_index, o.shard_count),
                    run_plan(e, plans, o.shard_index, o.shard_count).dump(1) + "\n");
  std::set<std::string> ran_now;
  int done = 0;
  for (const std::size_t i : execution_order(e, plans, o.shard_index, o.shard_count)) {
    const CellPlan& p = plans[i];
    if (const int signal = stop_requested()) throw RunStopped(signal, s, done);
    CellReport report;
    report.plan = &p;
    report.total = s.in_shard;
    if (!o.force && cell_finished(p.file)) {
      ++s.skipped;
      report.skipped = true;
      report.status = "skipped";
    } else {
      if (!o.force && fs::exists(p.file)) ++s.retried;
      const auto t0 = std::chrono::steady_clock::now();
      // The cell's frames, removed with the cell when it is dropped unless an earlier run left
      // them (a result of theirs may point to them).
      const fs::path frame_dir = out / "frames" / p.hash;
      std::error_code exists_ec;
      const bool had_frames = fs::exists(frame_dir, exists_ec);
      auto drop_cell = [&] {
        std::error_code ec;
        if (!had_frames) fs::remove_all(frame_dir, ec);
      };
      try {
        const json result = run_cell(e, p, meshes, out, budget, [&](int step) {
          if (o.on_step) o.on_step(StepReport{done + 1, s.in_shard, &p, step, p.cell.flow.steps});
          if (const int signal = stop_requested()) throw Interrupt{signal};
        });
        write_file_atomic(p.file, result.dump(1) + "\n");
        report.status = result.value("status", "error");
        report.error = result.value("error", "");
      } catch (const Interrupt& stop) {
        drop_cell();
        throw RunStopped(stop.signal, s, done);
      } catch (const std::exception& ex) {  // its frames or its result could not be written
        drop_cell();
        throw std::runtime_error(
            std::string(ex.what()) + "\nThe run stopped at cell " + std::to_string(p.cell.index) +
            "; its plan and the " + std::to_string(done) + " finished cell(s) in " + o.out_dir +
            " are kept. Rerun the same command to resume once " + o.out_dir + " can be written.");
      }
      ++s.ran;
      ran_now.insert(p.hash);
      if (report.status == "error") ++s.errors;
      report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    report.done = ++done;
    if (o.on_cell) o.on_cell(report);
  }

  // Distances to the reference flow once the cells are there. Only this shard's cells: a cell
  // file then has exactly one writer even when shards run at once on a shared file system.
  // A cell whose reference belongs to a shard that had not finished gets its distances on
  // the next run that includes it (e.g. `mcfbench run --distances-only` after a Slurm array).
  if (with_reference) {
    try {
      s.distances = add_reference_distances(e, o, plans, ran_now, stop_requested);
    } catch (const Interrupt& stop) {
      throw RunStopped(stop.signal, s, done);
    }
  }
  return s;
}

}  // namespace mcf
