// `mcfbench compare OLD NEW`: the flags of the regression check between two result sets
// (harness/compare.h: exit 1 when a cell got significantly slower or less accurate; sets of
// different machines refused unless --allow-cross-machine), NEW optionally stored in the
// performance history (`mcfbench history`).

#include "harness/compare.h"
#include "tools/commands.h"

#include <memory>

namespace mcf {

void add_compare_command(CLI::App& app, std::function<int()>& run) {
  auto a = std::make_shared<CompareRequest>();
  CLI::App* cmd = app.add_subcommand(
      "compare",
      "Compare two result sets cell by cell (speed and accuracy); exit 1 on a regression.");
  cmd->footer(
      "OLD and NEW are result folders, optionally DIR@COMMIT to pick one commit's results from a "
      "shared folder.\nEach repetition of a cell is one sample (its median step after the "
      "first); the U test needs at least 4 repetitions a side.");
  cmd->add_option("old", a->old_dir, "Baseline results folder[@commit]")->required();
  cmd->add_option("new", a->new_dir, "New results folder[@commit]")->required();
  cmd->add_option("--threshold", a->options.threshold,
                  "Relative change that counts (default 0.1 = 10%)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--alpha", a->options.alpha,
                  "Significance level of the Mann-Whitney U test (default 0.05)")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--metric", a->options.metric,
                  "Per-step value compared (dotted path in steps[]; default seconds.total; e.g. "
                  "seconds.solve)");
  cmd->add_flag("--all", a->options.show_all, "List unchanged cells in the table too");
  cmd->add_flag("--allow-cross-machine", a->options.allow_cross_machine,
                "Compare cells that ran on different machines, thread counts or builds (refused "
                "otherwise)");
  cmd->add_option("--history", a->history,
                  "Store NEW in this history store, keyed by machine, commit and study (no "
                  "value: data/history; see `mcfbench history`)")
      ->expected(0, 1);
  cmd->callback([cmd, a, &run] {
    run = [cmd, a]() -> int {
      a->store_history = cmd->count("--history") > 0;
      return compare_and_record(*a);
    };
  });
}

}  // namespace mcf
