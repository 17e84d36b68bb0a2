#pragma once
// `mcfbench submit CONFIG --out DIR`: runs an experiment matrix on a Slurm cluster. Writes the
// batch scripts (harness/slurm_script.h) into DIR/slurm/, submits a job array over the shards that
// still have cells to run and a job that collects the results and writes the report once the
// array has ended, and says how to follow them. Submitting again into the same folder, after
// tasks were lost (a time limit, a node failure, scancel), runs only the cells still missing or
// errored: finished cells are found by their result files, as `mcfbench run` skips them.

#include <string>
#include <vector>

namespace mcf {

struct SubmitRequest {
  std::string config;  ///< the experiment config (JSON)
  bool quick = false;  ///< the config's quick variant
  std::string out;     ///< the results folder (required)
  int tasks = 0;       ///< N, shards of the matrix; 0: one per cell, at most kMaxArrayTasks
  std::string partition, time, mem;  ///< sbatch's --partition, --time, --mem; empty: default
  int cpus_per_task = 1;             ///< CPUs of every job, and threads of every cell
  /// Slurm tasks of every array job, at least the cells' largest mpi_ranks; 0: that largest.
  int ntasks = 0;
  /// Nodes of every array job, its tasks spread over them; 0: Slurm's choice (no --nodes line).
  int nodes = 0;
  bool dry_run = false;                  ///< write the scripts, submit nothing
  std::vector<std::string> sbatch_args;  ///< passed to both sbatch calls as they are
  /// The binary the jobs run; empty: this process's own (/proc/self/exe).
  std::string mcfbench;
};

/// Slurm's default MaxArraySize is 1001 (task ids 0..1000); the default task count stays below.
inline constexpr int kMaxArrayTasks = 1000;

/// Checks the request's own values (before anything is read or written): the results folder is
/// given, tasks >= 0, cpus_per_task >= 1, every extra sbatch argument is an option in one word
/// (`--account=NAME`: a word on its own would be taken by sbatch for the script) and none sets
/// what submit sets itself (--array, --dependency, --cpus-per-task, --parsable, --wrap, their
/// short forms or abbreviations). Throws std::invalid_argument naming the argument.
void check_submit_request(const SubmitRequest& request);

/// Does the whole submission (see the file comment) and returns the exit status: 0 when it was
/// submitted (or written, with dry_run), 1 when sbatch refused (its own message went to stderr
/// as it wrote it, and nothing stays submitted: an array whose collect job was refused is
/// cancelled), or when jobs of the previous submission into the folder are still queued or
/// running. Throws for a bad request or config (before anything is submitted).
int submit_study(const SubmitRequest& request);

}  // namespace mcf
