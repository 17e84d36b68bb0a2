// `mcfbench expand CONFIG.json`: the flags of listing the cells of an experiment matrix without
// running them (harness/cell_listing.h).

#include "harness/cell_listing.h"
#include "tools/commands.h"

#include <cstdio>
#include <memory>

namespace mcf {

void add_expand_command(CLI::App& app, std::function<int()>& run) {
  auto a = std::make_shared<CellListingRequest>();
  CLI::App* cmd = app.add_subcommand(
      "expand",
      "List the cells of an experiment matrix (index, hash, assignment) without running.");
  cmd->add_option("config", a->config, "Experiment config (JSON)")->required();
  cmd->add_flag("--quick", a->quick, "Expand the config's \"quick\" variant");
  cmd->add_option("--threads", a->threads, "As for `run --threads` (changes the hashes)");
  cmd->add_flag("--json", a->json,
                "Print a JSON array (index, hash, key, repetition, assignment, config)");
  cmd->callback([a, &run] {
    run = [a]() -> int {
      std::printf("%s", cell_listing(*a).c_str());
      return 0;
    };
  });
}

}  // namespace mcf
