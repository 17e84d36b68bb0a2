// `mcfbench run CONFIG.json`: the flags of running an experiment matrix (or one shard of it),
// one result file per cell (harness/run_with_progress.h); rerunning skips finished cells and
// retries errored ones, so a killed or failed run is resumed by running it again.

#include "harness/run_with_progress.h"
#include "tools/commands.h"

#include <memory>

namespace mcf {

void add_run_command(CLI::App& app, std::function<int()>& run) {
  auto a = std::make_shared<RunRequest>();
  CLI::App* cmd = app.add_subcommand(
      "run", "Run the cells of an experiment matrix; one OUT/<hash>.json per cell.");
  cmd->footer(
      "Finished cells are skipped on a rerun and errored ones retried (--force redoes all); a "
      "killed run\n"
      "leaves no partial file. SIGINT or SIGTERM stops the run after the running step (exit 130 or "
      "143),\n"
      "dropping the running cell: rerun the same command to resume.\n"
      "Slurm: `mcfbench submit` writes and submits the job array and a job that collects and "
      "reports;\n"
      "by hand: sbatch --array=0-15 --wrap 'mcfbench run cfg.json --shard "
      "$SLURM_ARRAY_TASK_ID/16', then\n"
      "(with metrics.reference) `mcfbench run cfg.json --distances-only` adds the distances to "
      "reference\n"
      "cells that other shards computed, and `mcfbench collect results/NAME` checks that every "
      "cell is there.\n"
      "Config format: see harness/experiment_config.h and harness/configs/.");
  cmd->add_option("config", a->config, "Experiment config (JSON)")->required();
  cmd->add_option("--out", a->out,
                  "Results folder (default results/NAME, or results/NAME-quick with --quick)");
  cmd->add_option("--shard", a->shard,
                  "Run only cells with index % n == i (i/n, 0-based; default 0/1)");
  CLI::Option* force = cmd->add_flag("--force", a->force, "Rerun cells whose result file exists");
  cmd->add_flag("--distances-only", a->distances_only,
                "Run no cell: only add the reference distances the finished cells lack (after a "
                "sharded run)")
      ->excludes(force);
  cmd->add_flag("--quick", a->quick,
                "Use the config's \"quick\" variant (small, minutes on 2 cores)");
  cmd->add_option("--threads", a->threads,
                  "Override every cell's thread count (0 = all cores; changes the cell keys)")
      ->check(CLI::Range(0, 4096));
  cmd->add_option("--max-memory", a->max_memory,
                  "Refuse to start if a cell's estimated peak memory exceeds SIZE (8G, 512M; "
                  "none: no check; default: the memory available now)");
  cmd->callback([a, &run] { run = [a]() -> int { return run_experiment_with_progress(*a); }; });
}

}  // namespace mcf
