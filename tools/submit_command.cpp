// `mcfbench submit CONFIG.json --out DIR`: the flags of running an experiment matrix on a Slurm
// cluster, a job array over its shards and a job that collects and reports once the array has
// ended (harness/slurm_submit.h).

#include "harness/slurm_submit.h"
#include "tools/commands.h"

#include <memory>

namespace mcf {

void add_submit_command(CLI::App& app, std::function<int()>& run) {
  auto a = std::make_shared<SubmitRequest>();
  CLI::App* cmd = app.add_subcommand(
      "submit",
      "Run an experiment matrix on Slurm: a job array over its shards, then collect and report.");
  cmd->footer(
      "Writes DIR/slurm/run.sbatch (task i runs `mcfbench run CONFIG --shard i/N`) and\n"
      "DIR/slurm/collect.sbatch (after the array: reference distances, `mcfbench collect DIR`, "
      "the\n"
      "report in DIR/report), submits both with sbatch and prints their job ids. Submitting again\n"
      "into DIR runs only the cells still missing or errored (tasks lost to a time limit, a node\n"
      "failure, scancel). Options for sbatch itself follow `--`, one word each: -- --account=NAME");
  cmd->add_option("config", a->config, "Experiment config (JSON)")->required();
  cmd->add_flag("--quick", a->quick, "Use the config's \"quick\" variant");
  cmd->add_option("--out", a->out, "Results folder (also holds the scripts, logs and report)")
      ->required();
  cmd->add_option("--tasks", a->tasks,
                  "Array tasks N: task i runs the cells whose index % N == i (default: one per "
                  "cell, at most 1000)")
      ->check(CLI::Range(1, 1000000));
  cmd->add_option("--partition", a->partition, "sbatch --partition (default: the cluster's)");
  cmd->add_option("--time", a->time, "sbatch --time of every job, e.g. 2:00:00");
  cmd->add_option("--cpus-per-task", a->cpus_per_task,
                  "CPUs of every job, and every cell's thread count (part of its key; default 1)")
      ->check(CLI::Range(1, 4096));
  cmd->add_option("--mem", a->mem, "sbatch --mem of every job, e.g. 8G");
  cmd->add_option("--ntasks", a->ntasks,
                  "Slurm tasks (MPI ranks) of every array job (default: the largest mpi_ranks of "
                  "the cells; 1 writes no --ntasks line)")
      ->check(CLI::Range(1, 1000000));
  cmd->add_option("--nodes", a->nodes,
                  "Nodes of every array job, its tasks spread over them (a flow divided across "
                  "more memory than one node has; default: Slurm's choice)")
      ->check(CLI::Range(1, 1000000));
  cmd->add_flag("--dry-run", a->dry_run, "Write the scripts, submit nothing");
  cmd->add_option("sbatch_args", a->sbatch_args,
                  "Options passed to both sbatch calls, after --, one word each");
  cmd->callback([a, &run] { run = [a]() -> int { return submit_study(*a); }; });
}

}  // namespace mcf
