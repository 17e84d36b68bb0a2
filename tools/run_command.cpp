// `mcfbench run CONFIG.json`: run an experiment matrix (or one shard of it), one result file per
// cell; rerunning skips finished cells and retries errored ones, so a killed or failed run is
// resumed by running it again.

#include "bench/experiment_config.h"
#include "bench/runner.h"
#include "tools/commands.h"
#include "tools/progress.h"

#include <chrono>
#include <cstdio>
#include <memory>

namespace mcf {
namespace {

struct RunArgs {
  std::string config, out, shard = "0/1";
  bool force = false, quick = false;
  int threads = -1;
};

}  // namespace

void add_run_command(CLI::App& app, std::function<int()>& run) {
  auto a = std::make_shared<RunArgs>();
  CLI::App* cmd = app.add_subcommand(
      "run", "Run the cells of an experiment matrix; one OUT/<hash>.json per cell.");
  cmd->footer(
      "Finished cells are skipped on a rerun and errored ones retried (--force redoes all); a "
      "killed run\n"
      "leaves no partial file.\n"
      "Slurm: sbatch --array=0-15 --wrap 'mcfbench run cfg.json --shard $SLURM_ARRAY_TASK_ID/16'\n"
      "then `mcfbench collect results/NAME` checks that every cell is there (with "
      "metrics.reference, first\n"
      "run `mcfbench run cfg.json` once without --shard: every cell is skipped and the distances "
      "to the\n"
      "reference cells that other shards computed are added).\n"
      "Config format: see bench/experiment_config.h and bench/configs/.");
  cmd->add_option("config", a->config, "Experiment config (JSON)")->required();
  cmd->add_option("--out", a->out,
                  "Results folder (default results/NAME, or results/NAME-quick with --quick)");
  cmd->add_option("--shard", a->shard,
                  "Run only cells with index % n == i (i/n, 0-based; default 0/1)");
  cmd->add_flag("--force", a->force, "Rerun cells whose result file exists");
  cmd->add_flag("--quick", a->quick,
                "Use the config's \"quick\" variant (small, minutes on 2 cores)");
  cmd->add_option("--threads", a->threads,
                  "Override every cell's thread count (0 = all cores; changes the cell keys)")
      ->check(CLI::Range(0, 4096));
  cmd->callback([a, &run] {
    run = [a]() -> int {
      const ExperimentConfig e = load_experiment_config(a->config, a->quick);
      const double line_seconds =
          progress_line_seconds();  // a bad MCFBENCH_PROGRESS_SECONDS: nothing written
      RunOptions o;
      parse_shard(a->shard, o.shard_index, o.shard_count);
      o.out_dir = !a->out.empty() ? a->out : "results/" + e.name + (a->quick ? "-quick" : "");
      o.force = a->force;
      o.threads = a->threads;
      // One line per cell (not a \r progress bar): shard logs under Slurm stay readable.
      const auto start = std::chrono::steady_clock::now();
      double run_seconds = 0;
      int ran = 0;
      // Inside a running cell: its steps. on_cell ends the line (on a terminal the cell's own line
      // replaces it), so the next cell's first step starts a new one.
      std::unique_ptr<Progress> steps;
      o.on_step = [&](const StepReport& r) {
        if (!steps)
          steps = std::make_unique<Progress>("[" + std::to_string(r.cell_number) + "/" +
                                                 std::to_string(r.total) + "] cell " +
                                                 std::to_string(r.plan->cell.index) + " step",
                                             r.steps, line_seconds);
        steps->update(r.step);
      };
      o.on_cell = [&](const CellReport& r) {
        if (steps) steps->clear();
        steps.reset();
        const double elapsed =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (!r.skipped) {
          run_seconds += r.seconds;
          ++ran;
        }
        const double left = ran > 0 ? run_seconds / ran * (r.total - r.done) : 0.0;
        std::fprintf(
            stderr, "[%d/%d] cell %d %s %-8s %7.2f s  elapsed %.1f s  left ~%.1f s  %s%s%s\n",
            r.done, r.total, r.plan->cell.index, r.plan->hash.c_str(), r.status.c_str(), r.seconds,
            elapsed, left, r.plan->cell.assignment.dump().c_str(),
            r.plan->cell.repetition ? (" rep " + std::to_string(r.plan->cell.repetition)).c_str()
                                    : "",
            r.error.empty() ? "" : ("\n    error: " + r.error).c_str());
      };
      const RunSummary s = run_experiment(e, o);
      std::printf(
          "%s: %d cells, %d in shard %d/%d: %d ran%s, %d skipped, %d errors, %d reference "
          "distances; results in %s\n",
          e.name.c_str(), s.total, s.in_shard, o.shard_index, o.shard_count, s.ran,
          s.retried ? (" (" + std::to_string(s.retried) + " retried after an error)").c_str() : "",
          s.skipped, s.errors, s.distances, o.out_dir.c_str());
      return s.errors > 0 ? 1 : 0;
    };
  });
}

}  // namespace mcf
