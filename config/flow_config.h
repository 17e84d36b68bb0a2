#pragma once
// Every option of one flow run (config/config_values.h): reading it from JSON strictly, writing it
// back with every default, and the checks across options and against the mesh.

#include "config/config_values.h"
#include "datasets/mesh_spec.h"
#include "datasets/validate.h"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace mcf {

/// Reads a flow config strictly (unknown keys, wrong types, out-of-range values are errors that
/// name `source` and the key path) and fills defaults. Throws ConfigError.
FlowConfig flow_config_from_json(const nlohmann::json& j, const std::string& source);
/// The same without the cross-option checks (validate_flow_config): what a config asks for, to
/// be checked or amended (harness/experiment_config.cpp drops the defaults a cell's components do
/// not read).
FlowConfig flow_config_from_json_unchecked(const nlohmann::json& j, const std::string& source);
/// The dotted keys set to a value other than their default although no component of `c` reads
/// them (`--solver cholmod --cycles 7`), in the schema's order: what validate_flow_config refuses.
std::vector<std::string> inapplicable_keys(const FlowConfig& c);
/// The config as JSON with every default filled in (what result.json records).
nlohmann::json to_json(const FlowConfig& c);
/// Cross-option checks (e.g. cMCF and two-step integrators need a fixed basis).
void validate_flow_config(const FlowConfig& c, const std::string& source);
/// How the flow's mesh is loaded: zero-area faces removed (repair_degenerate), kept (the octree
/// basis, which integrates over the surface and needs no face's cotangents) or refused with a
/// message naming the option that goes on (the hat basis).
MeshLoadOptions mesh_load_options(const FlowConfig& c);
/// Checks of the config against its mesh (unit-area normalisation needs a closed surface).
/// Throws ConfigError naming `source` and the key.
void validate_flow_mesh(const FlowConfig& c, const MeshReport& mesh, const std::string& source);

}  // namespace mcf
