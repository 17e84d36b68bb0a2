#pragma once
// Every key of the flow config, gathered from the rows that own them (docs/extending.md): the
// flow's own keys, each basis row's, the options every solver shares and each solver row's own.
// flow_config_from_json, to_json, `mcfbench flow`'s flags and --help, and the option table of
// docs/flow.md are all made from this one list.

#include "config/option_spec.h"

#include <string>
#include <vector>

namespace mcf {

/// Every dotted key a flow config has and the objects that hold them ("mesh", "solver",
/// "solver.cycles", ...): every key a cell may set, whether or not result.json records it for the
/// cell's solver. Sorted.
const std::vector<std::string>& flow_config_keys();

/// The options in reading order: the config reader checks them in this order, so that of two bad
/// keys the first here is the one an error names. Keys of one object ("solver") are contiguous.
const std::vector<OptionSpec>& flow_config_schema();
/// The schema's option with this dotted key; throws std::out_of_range for a key it lacks.
const OptionSpec& option_spec(const std::string& key);

/// The values an option takes, as --help and docs/flow.md show them ("4..10", "V | W", "flag").
std::string option_values(const OptionSpec& o);
/// Its default as text ("0.5", "W", "the solver's: ...").
std::string option_default(const OptionSpec& o);
/// The --help line of a flag: help, values and default.
std::string option_flag_help(const OptionSpec& o);

/// The Markdown table of `mcfbench flow`'s config options in docs/flow.md (a test compares the
/// two; MCFBENCH_UPDATE_DOCS=1 on that test rewrites the page's table).
std::string flow_options_markdown();

}  // namespace mcf
