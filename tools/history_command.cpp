// `mcfbench history COMMAND ...`: every argument after `history` goes to the history tool
// (harness/history_tool.h, reports/perf_history.py), which parses it.

#include "harness/history_tool.h"
#include "tools/commands.h"

namespace mcf {

void add_history_command(CLI::App& app, std::function<int()>& run) {
  CLI::App* cmd = app.add_subcommand(
      "history",
      "Performance over commits: run, add, detect, bisect, ab, publish (scripts/history.sh).");
  cmd->footer(
      "mcfbench history run CONFIG A..B | run CONFIG --last N   build and run commits, store "
      "them\n"
      "mcfbench history add CONFIG RESULTS_DIR                   store a result set run by hand\n"
      "mcfbench history detect                                   step changes of every series\n"
      "mcfbench history bisect CONFIG --good A --bad B           the first slow commit\n"
      "mcfbench history ab CONFIG BASE HEAD --out DIR            alternate two commits, then "
      "compare\n"
      "mcfbench history publish OUT                              OUT/index.html, offline\n"
      "Options (see `mcfbench history COMMAND --help`): --store, --repo, --runner, --repetitions, "
      "--machine,\n"
      "--force, --last, --good, --bad, --threshold, --alpha, --min-run, --json, "
      "--fail-on-regression, "
      "--benchmark,\n"
      "--rounds, --out, --compare, --name. docs/history.md explains them.");
  // Everything after `history` (its subcommand, flags, --help) is the tool's to parse.
  cmd->prefix_command();
  cmd->callback(
      [cmd, &run] { run = [cmd]() -> int { return run_history_tool(cmd->remaining()); }; });
}

}  // namespace mcf
