// `mcfbench expand CONFIG.json`: list the cells of an experiment matrix without running them.

#include "bench/experiment_config.h"
#include "bench/runner.h"
#include "tools/commands.h"

#include <cstdio>
#include <memory>

namespace mcf {
namespace {

struct ExpandArgs {
  std::string config;
  bool quick = false, json = false;
  int threads = -1;
};

}  // namespace

void add_expand_command(CLI::App& app, std::function<int()>& run) {
  auto a = std::make_shared<ExpandArgs>();
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
      const ExperimentConfig e = load_experiment_config(a->config, a->quick);
      MeshCache meshes;  // the hash covers the input mesh's bytes, so meshes are loaded
      const auto plans = plan_cells(e, "", meshes, a->threads);
      if (a->json) {
        nlohmann::json list = nlohmann::json::array();
        for (const auto& p : plans)
          list.push_back({{"index", p.cell.index},
                          {"hash", p.hash},
                          {"key", p.key},
                          {"repetition", p.cell.repetition},
                          {"assignment", p.cell.assignment},
                          {"config", p.cell.config}});
        std::printf("%s\n", list.dump(1).c_str());
        return 0;
      }
      std::printf("# %s%s: %zu cells\n# index hash repetition assignment\n", e.name.c_str(),
                  a->quick ? " (quick)" : "", plans.size());
      for (const auto& p : plans)
        std::printf("%d %s %d %s\n", p.cell.index, p.hash.c_str(), p.cell.repetition,
                    p.cell.assignment.dump().c_str());
      return 0;
    };
  });
}

}  // namespace mcf
