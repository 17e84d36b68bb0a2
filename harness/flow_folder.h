#pragma once
// `mcfbench flow`: one flow, written to OUT/result.json and OUT/final.ply (+ frames).
// Frames and final.ply are staged in OUT/.mcfbench-staging while the flow runs and moved into OUT
// only once it has finished, result.json last: an interrupted or failed run into an existing OUT
// leaves the previous run's files as they were, never its result beside the new run's frames.

#include <nlohmann/json.hpp>

#include <string>
#include <utility>
#include <vector>

namespace mcf {

struct FlowRequest {
  std::string config_file;  ///< a JSON flow config to start from; empty: none
  /// Keys set on top of it, in order: a dotted path ("octree.depth") and its value. The command
  /// line gives one per flag it was given, so the config file supplies the rest.
  std::vector<std::pair<std::string, nlohmann::json>> settings;
  std::string out;  ///< the output folder
  /// The memory budget (harness/memory_budget.h): "" = what is available, "none", or a size.
  std::string max_memory;
};

/// Assembles one flow config from the request and validates it in one place
/// (flow_config_from_json, so the command line and experiment configs agree), loads the mesh,
/// refuses a flow whose estimated peak memory exceeds the budget (before the mesh is generated,
/// from the spec's sizes, and again once it is loaded), runs the flow with its progress on stderr
/// and publishes its files into `out`; one line on stderr says how the flow ended, and one per
/// note of the mesh's loading (faces reoriented, zero-area faces collapsed or kept). Throws on a
/// configuration or set-up error, before anything is written or removing what this run created.
/// SIGINT or SIGTERM stops the flow after the running step (harness/stop_signals.h): its staged
/// files are removed, `out` keeps what it held (or is removed when this run created it), a line
/// on stderr says so, and 128 + the signal is returned; else 0.
int run_flow_into_folder(const FlowRequest& request);

}  // namespace mcf
