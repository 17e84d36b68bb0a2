#pragma once
// Experiments: the cells of an experiment config run into a results folder, as `mcfbench run`
// does, and a folder's cells read back as one table (docs/experiments.md).

#include "mcfbench/export.h"
#include "mcfbench/types.h"

#include <optional>
#include <string>
#include <vector>

namespace mcfbench {

struct RunOptions {
  std::string out;            ///< results folder (required)
  bool quick = false;         ///< the config's "quick" variant
  std::string shard = "0/1";  ///< "i/n": only the cells with index % n == i
  bool force = false;         ///< rerun cells whose result file exists
  int threads = -1;           ///< >= 0 overrides every cell's thread count (changes their keys)
  std::string max_memory;     ///< as Options::max_memory, checked for every cell to run
};

/// Runs the cells of `config` (an experiment config file) in this process, with `mcfbench run`'s
/// progress on stderr and its summary line on stdout; a solver registered with register_solver
/// is a value its "solver.name" axis may take. Finished cells are skipped, so a stopped run
/// resumes. Returns 0 when every cell ran, 1 when a cell ended in an error (its result file says
/// which), 128 + the signal when SIGINT or SIGTERM stopped the run after a step (the running
/// cell dropped). Throws InputError on a bad config before anything is written. Cells with
/// mpi_ranks > 1 need the `mcfbench` command (they start it under mpirun).
MCFBENCH_API int run(const std::string& config, const RunOptions& options);

/// A results folder as a table: one row per cell result file (DIR/<hash>.json), ordered by cell
/// index and repetition.
struct ResultsTable {
  /// The flow config's keys first ("mesh", "solver.name", "dt", ...), then the cell's
  /// ("cell.index", "cell.repetition", "cell.hash", ...), then every other scalar of the result
  /// file by its dotted path ("status", "stop.reason", "timing.step_median_seconds",
  /// "peak_memory_bytes", "reference_distance.rms", ...); per-step records, the study config and
  /// the library versions are left out.
  std::vector<std::string> columns;
  /// rows[r][c]: the value of columns[c] in row r; empty where that file lacks it.
  std::vector<std::vector<std::optional<Value>>> rows;
};

/// Reads every cell result of `folder` (not its plans, frames or index). Throws InputError naming
/// the folder when it does not exist, or a file that does not parse.
MCFBENCH_API ResultsTable results(const std::string& folder);

}  // namespace mcfbench
