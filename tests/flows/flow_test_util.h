#pragma once
// Runs flows from a JSON config inside tests.

#include "config/flow_config.h"
#include "datasets/mesh_spec.h"
#include "flows/flow.h"

#include <nlohmann/json.hpp>

namespace mcf::testing {

inline FlowOutcome run(const nlohmann::json& j) {
  const FlowConfig c = flow_config_from_json(j, "test");
  return run_flow(c, load_mesh_spec(c.mesh));
}

inline double last(const FlowOutcome& o, const char* group, const char* key) {
  return o.result["steps"].back()[group][key].get<double>();
}

/// Mean distance of the vertices to the origin.
inline double mean_radius(const Positions& V) {
  return V.rowwise().norm().mean();
}

}  // namespace mcf::testing
