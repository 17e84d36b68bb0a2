// `mcfbench collect DIR...`: the flags of merging result folders into one index file and
// checking that every cell is there once (harness/collect.h).

#include "harness/collect.h"
#include "tools/commands.h"

#include <memory>

namespace mcf {
namespace {

struct CollectArgs {
  std::vector<std::string> dirs;
  std::string out;
};

}  // namespace

void add_collect_command(CLI::App& app, std::function<int()>& run) {
  auto a = std::make_shared<CollectArgs>();
  CLI::App* cmd = app.add_subcommand(
      "collect",
      "Merge result folders (shards) into an index file; check for missing and duplicate cells.");
  cmd->add_option("dirs", a->dirs, "Result folders")->required();
  cmd->add_option("--out", a->out, "Index file (default FIRST_DIR/index.json)");
  cmd->callback([a, &run] { run = [a]() -> int { return collect_results(a->dirs, a->out); }; });
}

}  // namespace mcf
