#include "harness/flow_plan.h"

#include <utility>

namespace mcf {

FlowPlan prepare_flow(FlowConfig config, std::string what) {
  FlowPlan plan;
  plan.mesh = parse_mesh_spec(config.mesh);
  plan.what = what.empty() ? config.mesh : std::move(what);
  plan.config = std::move(config);
  return plan;
}

MemoryEstimate estimate_flow(const FlowPlan& plan, const MemoryBudget& budget) {
  return checked_memory_estimate(plan.config, spec_sizes(plan.mesh), budget, plan.what);
}

MeshSource load_flow_mesh(const FlowPlan& plan) {
  return load_mesh_spec(plan.mesh, mesh_load_options(plan.config));
}

MemoryEstimate check_loaded_flow(const FlowPlan& plan, const MeshSource& mesh,
                                 const MemoryBudget& budget) {
  validate_flow_mesh(plan.config, mesh.report, plan.what);
  return checked_memory_estimate(plan.config, mesh_sizes(plan.config, mesh.mesh, mesh.analytic),
                                 budget, plan.what);
}

}  // namespace mcf
