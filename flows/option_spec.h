#pragma once
// One key of the flow config as a row declares it: its type, default, range or allowed values,
// help text, command-line flag and where it lives in FlowConfig. The rows' options are what
// result.json records, what the config reader accepts and what `mcfbench flow` offers.

#include "flows/flow_config.h"

#include <nlohmann/json.hpp>

#include <functional>
#include <string>
#include <vector>

namespace mcf {

enum class OptionType { string, integer, number, boolean };

struct OptionSpec {
  std::string key;  ///< its key in its object ("stall_ratio" under "solver")
  OptionType type = OptionType::string;
  nlohmann::json fallback;  ///< the default
  double min = 0, max = 0;  ///< integer and number: the range taken
  std::string help;
  std::string flag;  ///< the `mcfbench flow` flag ("--stall-ratio")
  std::function<nlohmann::json(const FlowConfig&)> get;
  std::function<void(FlowConfig&, const nlohmann::json&)> set;
  /// A value other than the default is refused unless the row that owns the option is selected
  /// (a value no component reads would be recorded as if it had shaped the run).
  bool refused_elsewhere = false;
};

class ConfigReader;
/// Reads `option` from `reader`'s object into `config` (its current value is the default), with
/// the reader's strict checks of type and range.
void read_option(ConfigReader& reader, const OptionSpec& option, FlowConfig& config);

}  // namespace mcf
