#pragma once
// An experiment matrix (a study config under harness/configs/) and its expansion into cells.
//
//   { "name": "...", "description": "...", "paper": <free>,
//     "defaults": {flow config, same keys as result.json's "config"},
//     "axes": {"solver.cycles": [1, 2], "mesh": ["a", "b"]},      // cartesian product
//     "zip": [ {"basis": ["hat", "octree"], "solver.name": ["cholmod", "multigrid"]} ],
//     "exclude": [ {"basis": "hat", "octree.depth": 9} ],
//     "repetitions": 1, "interleave": true, "order_seed": 1,
//     "metrics": {"quasi_conformal": true, "sphericity": true, "every": 10,
//                 "frames": [1, 10, 100], "reference": {"basis": "hat"}, "distance_samples":
//                 20000},
//     "quick": {"defaults": {...}, "axes": {...}, "zip": [...], "exclude": [...], "repetitions": 1}
//     }
//
// Expansion order is fixed (axes in sorted key order, last key fastest; then each zip group as
// one more dimension; repetitions innermost), so a cell's index — and hence `--shard i/n` —
// means the same thing in every process that reads the same file.

#include "config/flow_config.h"
#include "harness/json_path.h"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace mcf {

/// The "metrics" object: what the runner computes besides what the flow records itself.
struct MetricsConfig {
  bool quasi_conformal = false;
  bool sphericity = false;
  int every = 1;  ///< per-step metrics every K steps (and at the last step, or a stopped flow's
                  ///< last completed one)
  std::vector<int> frames;  ///< steps whose meshes are saved as frames/<hash>/frame_NNNNN.ply
  nlohmann::json
      reference;  ///< partial assignment {dotted key: value} of the reference cell; null = none
  long long distance_samples = 20000;  ///< samples per side for the distance to the reference
};

struct Cell {
  int index = 0;  ///< position in expansion order (0-based)
  int repetition = 0;
  nlohmann::json assignment;  ///< {dotted key: value} of the axes and zip keys of this cell
  nlohmann::json config;      ///< full flow config, defaults filled (to_json(flow))
  FlowConfig flow;
};

struct ExperimentConfig {
  std::string source;  ///< file name (for messages)
  std::string name, description;
  bool quick = false;  ///< the quick variant was expanded
  int repetitions = 1;
  /// With repetitions > 1, run every cell once in a shuffled order, then every cell again in
  /// another, instead of a cell's repetitions back to back: slow drift of the machine (thermal
  /// state, other tenants) then spreads over all cells instead of biasing some. The order is fixed
  /// by `order_seed` (and the round), so a rerun or a resumed run walks the same order.
  bool interleave = true;
  long long order_seed = 1;
  MetricsConfig metrics;
  nlohmann::json study_config;  ///< the whole file as read (stored in every result)
  std::vector<Cell> cells;
};

/// Parses and expands; every problem throws ConfigError naming `source` and the dotted key path
/// (e.g. "cfg.json: defaults.solver.cycels: unknown key"). `default_name` is used when the file
/// has no "name" (the file's stem).
ExperimentConfig parse_experiment_config(const nlohmann::json& j, const std::string& source,
                                         bool quick, const std::string& default_name = "study");
/// Reads the file (parse errors name it) and calls parse_experiment_config.
ExperimentConfig load_experiment_config(const std::string& path, bool quick);

/// True if the cell's full config has every {dotted key: value} of `partial`.
bool matches_assignment(const Cell& cell, const nlohmann::json& partial);

}  // namespace mcf
