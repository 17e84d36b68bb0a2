#pragma once
// One flow from its config to its outcome, in the four steps every caller takes in this order
// (`mcfbench flow` through harness/flow_folder.h, the library's mcfbench::flow, each cell of
// `mcfbench run`):
//
//   prepare   prepare_flow: the config as read (config/flow_config.h) with its mesh spec parsed
//             and checked, once;
//   estimate  estimate_flow: its peak memory from the spec's sizes, refused over the budget before
//             any mesh is generated or read;
//   load      load_flow_mesh: the mesh as the config loads it (zero-area faces), then
//             check_loaded_flow: the mesh against the config and the memory again from its own
//             sizes, before any basis is built;
//   run       run_flow (flows/flow.h) in one process, dist::run_distributed_flow across ranks.
//
// Each step throws naming `FlowPlan::what` (a ConfigError, MeshError or MemoryLimitError) and
// writes nothing.

#include "config/flow_config.h"
#include "config/memory_estimate.h"
#include "datasets/mesh_spec.h"
#include "harness/memory_budget.h"

#include <string>

namespace mcf {

struct FlowPlan {
  FlowConfig config;
  MeshSpecRequest mesh;  ///< config.mesh, parsed
  std::string what;      ///< what errors name: the mesh spec, or a cell of a study and its mesh
};

/// prepare: `config`'s mesh spec parsed (MeshError naming it on a malformed spec). `what`: empty
/// for the spec itself.
FlowPlan prepare_flow(FlowConfig config, std::string what = "");
/// estimate: the flow's peak memory on a mesh of the spec's sizes with what this process holds
/// now; MemoryLimitError naming `plan.what` where it exceeds `budget`.
MemoryEstimate estimate_flow(const FlowPlan& plan, const MemoryBudget& budget);
/// load: the mesh of the plan's spec, read or generated without parsing the spec again, its
/// zero-area faces treated as the config says (mesh_load_options).
MeshSource load_flow_mesh(const FlowPlan& plan);
/// The loaded mesh against the config (validate_flow_mesh: ConfigError naming `plan.what`), and
/// the estimate again from the mesh's own sizes: returned where it fits `budget`.
MemoryEstimate check_loaded_flow(const FlowPlan& plan, const MeshSource& mesh,
                                 const MemoryBudget& budget);

}  // namespace mcf
