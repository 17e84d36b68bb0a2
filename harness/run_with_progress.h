#pragma once
// `mcfbench run CONFIG.json`: runs an experiment matrix (or one shard of it), one result file per
// cell (harness/runner.h), with its progress on stderr: one line per cell (not a \r progress bar:
// shard logs under Slurm stay readable) and, inside a running cell, its steps; a summary line on
// stdout at the end.

#include <string>

namespace mcf {

struct RunRequest {
  std::string config;  ///< the experiment config (JSON)
  std::string out;     ///< results folder; empty: results/NAME (results/NAME-quick with quick)
  std::string shard = "0/1";    ///< "i/n": only cells with index % n == i
  bool force = false;           ///< rerun cells whose result file exists
  bool quick = false;           ///< the config's "quick" variant
  int threads = -1;             ///< >= 0 overrides every cell's thread count
  bool distances_only = false;  ///< run no cell, only add missing reference distances
  std::string max_memory;       ///< memory budget: "" = what is available, "none", or a size
};

/// Runs the request's cells; returns 1 when a cell errored, else 0. A config error (or a bad
/// MCFBENCH_PROGRESS_SECONDS) throws before anything is written. SIGINT or SIGTERM stops the run
/// after the running step (harness/stop_signals.h): the running cell is dropped, a message on
/// stderr says how to resume, and it returns 128 + the signal's number (130, 143) as a shell
/// reports a process that signal ended.
int run_experiment_with_progress(const RunRequest& request);

}  // namespace mcf
