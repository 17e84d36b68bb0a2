// `mcfbench compare OLD NEW`: regression check between two result sets (exit 1 when a cell got
// significantly slower or less accurate), optionally appended to a history file.

#include "bench/compare.h"
#include "tools/commands.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>

namespace mcf {
namespace {

struct CompareArgs {
  std::string old_dir, new_dir, history;
  CompareOptions options;
};

}  // namespace

void add_compare_command(CLI::App& app, std::function<int()>& run) {
  auto a = std::make_shared<CompareArgs>();
  CLI::App* cmd = app.add_subcommand(
      "compare",
      "Compare two result sets cell by cell (speed and accuracy); exit 1 on a regression.");
  cmd->footer(
      "OLD and NEW are result folders, optionally DIR@COMMIT to pick one commit's results from a "
      "shared folder.");
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
  cmd->add_option("--history", a->history,
                  "Append one JSON line for NEW to this file (no value: results/history.jsonl)")
      ->expected(0, 1);
  cmd->callback([cmd, a, &run] {
    run = [cmd, a]() -> int {
      const ResultSet old_set = load_result_set(a->old_dir, a->options.metric);
      const ResultSet new_set = load_result_set(a->new_dir, a->options.metric);
      const CompareReport r = compare_results(old_set, new_set, a->options);
      std::printf("%s", compare_markdown(r, old_set, new_set, a->options).c_str());
      if (cmd->count("--history") > 0) {
        const std::string file = a->history.empty() ? "results/history.jsonl" : a->history;
        const std::filesystem::path p(file);
        if (p.has_parent_path()) std::filesystem::create_directories(p.parent_path());
        std::ofstream out(file, std::ios::app);
        out << history_entry(new_set, a->options.metric).dump() << "\n";
        if (!out) throw std::runtime_error(file + ": cannot append");
      }
      return r.regression ? 1 : 0;
    };
  });
}

}  // namespace mcf
