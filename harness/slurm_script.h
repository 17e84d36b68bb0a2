#pragma once
// The batch scripts `mcfbench submit` writes into RESULTS/slurm/: a job array whose task i runs
// shard i/N of an experiment matrix, and a job that, once the array has ended, adds the reference
// distances the tasks could not compute, checks the results (`mcfbench collect`) and writes the
// report. Plain bash with #SBATCH lines and comments saying what each does, so that a user can
// read them, and submit them again by hand. Every path in them is absolute: a job does not depend
// on the folder it was submitted from.

#include <string>
#include <vector>

namespace mcf {

/// Where `mcfbench submit` keeps its files in a results folder.
struct SlurmPaths {
  std::string folder;          ///< OUT/slurm
  std::string run_script;      ///< OUT/slurm/run.sbatch: the job array
  std::string collect_script;  ///< OUT/slurm/collect.sbatch: the collect-and-report job
  std::string logs;            ///< OUT/slurm/logs: the jobs' output
  std::string record;          ///< OUT/slurm/submitted.json: the last submission's jobs
  std::string report;          ///< OUT/report: where the collect job writes the report
};
SlurmPaths slurm_paths(const std::string& out_dir);

/// Resources of every job of a submission (the array's tasks and the collect job alike).
struct SlurmJobSettings {
  std::string partition, time, mem;  ///< empty: the cluster's default
  int cpus_per_task = 1;             ///< also the thread count of every cell (part of its key)
  /// Slurm tasks of each array job: the MPI ranks its cells' flows run on (a cell with
  /// mpi_ranks P starts mpirun -n P inside the job's allocation). 1: no --ntasks line.
  int ntasks = 1;
  /// Nodes of each array job, over which Slurm spreads its tasks (a flow divided across ranks
  /// larger than one node's memory). 0: no --nodes line (Slurm's choice).
  int nodes = 0;
};

struct BatchScriptInput {
  std::string study;            ///< names the jobs
  bool quick = false;           ///< the config's quick variant
  std::string mcfbench;         ///< absolute path of the binary the jobs run
  std::string config;           ///< absolute path of the experiment config
  std::string out_dir;          ///< absolute path of the results folder
  int cells = 0;                ///< cells of the matrix (for the comments)
  int tasks = 1;                ///< N: task i runs the cells whose index % N == i
  std::vector<int> array;       ///< the tasks to run now: sorted, distinct, each in [0, N)
  bool with_reference = false;  ///< metrics.reference: the collect job adds missing distances
  std::string report_script;    ///< reports/make_report.py; empty: the collect job writes none
  std::string python = "/usr/bin/python3";  ///< runs the report script
  std::string resubmit;  ///< the shell command that submits again, named where cells are missing
  SlurmJobSettings job;
};

/// `word` as one word of a bash command line: as it is when it holds only characters the shell
/// leaves alone, else in single quotes (a single quote inside written '\'').
std::string shell_quote(const std::string& word);
/// The words, each quoted, joined by spaces.
std::string shell_join(const std::vector<std::string>& words);

/// Slurm's --array value for sorted distinct task ids: "0-2", "1,4-6,9".
std::string array_spec(const std::vector<int>& tasks);

/// The job array's script (submitted with `sbatch --parsable SCRIPT`). Throws
/// std::invalid_argument when the results folder's path holds a character an #SBATCH line
/// cannot carry (a double quote, a backslash, a line break), naming it.
std::string run_array_script(const BatchScriptInput& in);
/// The collect-and-report job's script (submitted with `--dependency=afterany:ARRAY_ID`). Exits 0
/// when every cell is there once and none errored, else 1 (after writing the report all the same,
/// marked incomplete, and naming the command that runs the cells still missing). Throws as
/// run_array_script.
std::string collect_script(const BatchScriptInput& in);

}  // namespace mcf
