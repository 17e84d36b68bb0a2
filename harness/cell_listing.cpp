#include "harness/cell_listing.h"

#include "harness/experiment_config.h"
#include "harness/runner.h"

#include <nlohmann/json.hpp>

namespace mcf {

std::string cell_listing(const CellListingRequest& request) {
  const ExperimentConfig e = load_experiment_config(request.config, request.quick);
  MeshCache meshes;
  const auto plans = plan_cells(e, "", meshes, request.threads);
  if (request.json) {
    nlohmann::json list = nlohmann::json::array();
    for (const auto& p : plans)
      list.push_back({{"index", p.cell.index},
                      {"hash", p.hash},
                      {"key", p.key},
                      {"repetition", p.cell.repetition},
                      {"assignment", p.cell.assignment},
                      {"config", p.cell.config}});
    return list.dump(1) + "\n";
  }
  std::string text = "# " + e.name + (request.quick ? " (quick)" : "") + ": " +
                     std::to_string(plans.size()) + " cells\n# index hash repetition assignment\n";
  for (const auto& p : plans)
    text += std::to_string(p.cell.index) + " " + p.hash + " " + std::to_string(p.cell.repetition) +
            " " + p.cell.assignment.dump() + "\n";
  return text;
}

}  // namespace mcf
