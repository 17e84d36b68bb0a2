#pragma once
// `mcfbench run`: runs the cells of an experiment matrix (or one shard of them), one result
// file per cell, named by the cell hash and written atomically, so an interrupted or killed
// run is resumed by running it again (finished cells are skipped, the killed one is redone, and a
// cell whose result is an error is retried).

#include "datasets/mesh_spec.h"
#include "harness/experiment_config.h"

#include <nlohmann/json.hpp>

#include <functional>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace mcf {

/// A cell with its names: key (no code version; `compare` matches on it), hash (file name).
struct CellPlan {
  Cell cell;
  std::string mesh_fingerprint, key, hash;
  std::string config_key;  ///< key without the repetition: `compare` pools repetitions under it
  std::string file;        ///< OUT/<hash>.json
};

/// Meshes are loaded once per spec (and treatment of zero-area faces) per process (hashing needs
/// the loaded mesh's bytes).
class MeshCache {
 public:
  /// The mesh of a flow, loaded as that flow loads it: prepare_flow and load_flow_mesh
  /// (harness/flow_plan.h) the first time, the same mesh for every later flow of its spec and
  /// treatment of zero-area faces (mesh_load_options).
  const MeshSource& get(const FlowConfig& flow);

 private:
  std::map<std::string, std::shared_ptr<MeshSource>> meshes_;
};

struct CellReport {
  int done = 0, total = 0;  ///< cells of this shard finished so far (run or skipped) / in the shard
  const CellPlan* plan = nullptr;
  bool skipped = false;
  std::string status;  ///< ok | singular | error | skipped
  std::string error;
  double seconds = 0;
};

/// A cell's flow has finished step `step` of `steps` (0 = the input, before the first step).
struct StepReport {
  int cell_number = 0,
      total = 0;  ///< this cell's place among the shard's cells (1-based) / their number
  const CellPlan* plan = nullptr;
  int step = 0, steps = 0;
};

struct RunOptions {
  std::string out_dir;
  int shard_index = 0, shard_count = 1;
  bool force = false;
  int threads = -1;  ///< >= 0 overrides every cell's "threads" (part of the config, so of the key)
  /// Runs no cell and writes no plan: only adds the reference distances (metrics.reference) that
  /// the finished cells of the shard lack, as after a job array whose tasks could not see each
  /// other's cells. Cells without a finished result are counted in RunSummary::not_run.
  bool distances_only = false;
  /// The memory budget (harness/memory_budget.h): "" = what is available, "none", or a size. A cell
  /// this shard would run whose estimated peak exceeds it stops the run before anything is written.
  std::string max_memory;
  std::function<void(const CellReport&)> on_cell;  ///< progress (stderr in the CLI)
  /// Progress of the reference distances: `done` of `total` cells, the last one's index.
  std::function<void(int done, int total, int cell_index)> on_distance;
  std::function<void(const StepReport&)>
      on_step;  ///< inside a cell that runs (not for skipped ones)
  /// Asked before each cell and after each step of a running cell: nonzero (the signal that asked,
  /// see harness/stop_signals.h) stops the run there with RunStopped.
  std::function<int()> stop_requested;
};

struct RunSummary {
  int total = 0, in_shard = 0, ran = 0, skipped = 0, errors = 0, distances = 0;
  int not_run = 0;  ///< with distances_only: cells of the shard without a finished result
  int retried = 0;  ///< of `ran`: cells whose file held an error (or did not parse), run again
};

/// The code version stored in hashes: the git commit the binary was built from.
std::string code_version();
/// Whether a cell's result file counts as done on a rerun: it holds a result that did not error.
/// A missing file, an errored cell and a file that does not parse (written by something else than
/// the atomic writer) are not done: a rerun runs them.
bool cell_finished(const std::string& file);
/// Shard membership: cell index % n == i.
bool in_shard(int index, int shard_index, int shard_count);
/// Parses "i/n" (0 <= i < n); throws std::invalid_argument with a message otherwise.
void parse_shard(const std::string& text, int& shard_index, int& shard_count);

/// Names every cell (loading the meshes of the cells `wanted` selects, all if empty).
/// `threads` >= 0 overrides the cells' thread count. A mesh that fails to load throws,
/// naming the config file and the cell.
std::vector<CellPlan> plan_cells(const ExperimentConfig& e, const std::string& out_dir,
                                 MeshCache& meshes, int threads = -1,
                                 const std::function<bool(const Cell&)>& wanted = {});

std::string run_plan_path(const std::string& out_dir, const ExperimentConfig& e, int shard_index,
                          int shard_count);
inline constexpr const char* kPlanFolder = "plans";

/// Thrown by run_experiment when RunOptions::stop_requested asked it to stop. The cell that was
/// running is dropped (no result file; the frames it had written are removed); the plan and the
/// results of the cells before it stay, so the same run resumes where it stopped.
struct RunStopped : std::runtime_error {
  RunStopped(int signal, const RunSummary& summary, int done);
  int signal;          ///< what stop_requested returned
  RunSummary summary;  ///< the cells ran and skipped before the stop
  int done;            ///< cells of the shard with a result from this run or an earlier one
};

/// The order in which `run` walks the shard's cells, as indices into `plans`: expansion order, or
/// with ExperimentConfig::interleave and repetitions > 1 one round per repetition, each round the
/// cells of that repetition in a shuffled order (Fisher-Yates on a 64-bit Mersenne Twister seeded
/// by order_seed and the round: the same on every platform). Cell indices and hashes do not
/// change, so shards and resumed runs mean the same cells.
std::vector<std::size_t> execution_order(const ExperimentConfig& e,
                                         const std::vector<CellPlan>& plans, int shard_index = 0,
                                         int shard_count = 1);

/// Runs the shard. Config problems throw before anything is written; an exception inside one
/// cell's flow becomes that cell's result {"status": "error", "error": ...} and the run goes on.
/// A file that cannot be written (the plan, a cell's result or frames: a full disk, a read-only
/// folder) stops the run with std::runtime_error naming the file and the cause: the running cell
/// is dropped as for RunStopped, finished cells stay.
RunSummary run_experiment(const ExperimentConfig& e, const RunOptions& options);

}  // namespace mcf
