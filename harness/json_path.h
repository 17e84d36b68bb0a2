#pragma once
// Dotted paths into JSON objects ("solver.cycles"): how flow configs, experiment cells and result
// files name a value. The flow config's own keys are flow_config_keys (config/config_schema.h).

#include <nlohmann/json.hpp>

#include <string>

namespace mcf {

/// Value at a dotted path in a JSON object (nullptr if absent).
const nlohmann::json* json_at_path(const nlohmann::json& j, const std::string& dotted);
/// Sets a value at a dotted path, creating objects on the way.
void set_json_path(nlohmann::json& j, const std::string& dotted, const nlohmann::json& value);
/// Removes the value at a dotted path, if there is one (objects on the way stay, even if empty).
void erase_json_path(nlohmann::json& j, const std::string& dotted);

}  // namespace mcf
