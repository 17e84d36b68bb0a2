#pragma once
// One key of the flow config as the row it belongs to declares it: type, default, range or
// allowed values, help text, `mcfbench flow` flag, where it lives in FlowConfig and when
// result.json records it. The config reader, `to_json`, the command line, its --help and the
// option table of docs/flow.md are all made from these (config/config_schema.h).

#include "config/config_values.h"

#include <nlohmann/json.hpp>

#include <functional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace mcf {

class ConfigReader;

enum class OptionType { string, integer, number, boolean };

/// When result.json's "config" records an option.
enum class Recorded {
  always,
  /// Only where the row that owns it is selected (a solver's own options), and
  when_selected,
  /// only with a value other than its default: a key present with its default would change the
  /// config key of every cell (harness/cell_hash.h), and `compare` would find no cell of an earlier
  /// run to compare with.
  when_set,
};

/// How `mcfbench flow` takes an option.
enum class FlagKind {
  value,      ///< --flag VALUE
  set_true,   ///< --flag sets it true
  set_false,  ///< --flag sets it false (--frozen: extrapolate false)
};

/// A value of a string option with a fixed set: the value and one line on what it does.
using Choice = std::pair<std::string, std::string>;

struct OptionSpec {
  std::string key;  ///< dotted: "solver.stall_ratio"
  OptionType type = OptionType::string;
  nlohmann::json fallback;  ///< the default
  double min = 0, max = 0;  ///< integer and number options: the range taken
  std::string help;         ///< one sentence, for --help and docs/flow.md
  std::string flag;         ///< "--stall-ratio"; empty: config key only
  /// A string option with a fixed set of values: those values (a table's rows).
  std::function<std::vector<Choice>()> choices{};
  /// Where the default is not one value ("the solver's"): what the docs and --help say instead.
  std::string default_text{};
  /// Where the range alone says too little ("1 | 3 | 6"): the values, as the docs show them.
  std::string values_text{};
  FlagKind flag_kind = FlagKind::value;
  /// Optional: the flag's text as the config's value (--blas-threads auto); throws
  /// std::invalid_argument with the message.
  std::function<nlohmann::json(const std::string&)> parse_flag{};
  std::function<nlohmann::json(const FlowConfig&)> get{};
  std::function<void(FlowConfig&, const nlohmann::json&)> set{};
  Recorded recorded = Recorded::always;
  /// A value other than its default is refused unless the owner is selected (a value no
  /// component reads would be recorded as if it had shaped the run).
  bool refused_elsewhere = false;
  /// Optional: runs after the value is read (cubature's 1 | 3 | 6, dt > 0, a solver's own
  /// defaults) and reports through the reader (`leaf` is the key within its object).
  std::function<void(FlowConfig&, const ConfigReader& reader, const std::string& leaf)> after{};
  /// The row that owns a `when_selected` option ("multigrid"), and whether a config selects it;
  /// flow_config_schema() fills both.
  std::string owner{};
  /// What a refusal names as the owner: `solver "petsc"`, "a multigrid (...)".
  std::string owner_text{};
  std::function<bool(const FlowConfig&)> selected{};
  /// In an experiment matrix, a value set on a cell whose components do not read it is dropped
  /// (the cell records the default, as for a default) instead of refused: a basis's options,
  /// which a study sets per mesh or per axis across bases (harness/experiment_config.h).
  bool matrix_drops = false;
  /// What a refusal names as in use instead (`the basis is "hat"`); empty: the solver.
  std::function<std::string(const FlowConfig&)> in_use{};
};

/// An option with its key, type, default, flag and help; the rest as OptionSpec's defaults.
OptionSpec option(std::string key, OptionType type, nlohmann::json fallback, std::string flag,
                  std::string help);
/// `o` taking values in [min, max] (integer and number options).
OptionSpec ranged(OptionSpec o, double min, double max);

/// `o` bound to the field `ref` returns (a generic lambda, `[](auto& c) -> auto& { return
/// c.octree.depth; }`, so that it serves const and mutable configs).
template <class Ref>
OptionSpec bind(OptionSpec o, Ref ref) {
  o.get = [ref](const FlowConfig& c) { return nlohmann::json(ref(c)); };
  o.set = [ref](FlowConfig& c, const nlohmann::json& v) {
    auto& field = ref(c);
    field = v.get<std::decay_t<decltype(field)>>();
  };
  return o;
}

/// A solver row's own option `o` (its key the row-local leaf, "omega") kept in
/// SolverConfig::params instead of a field of its own, so that a solver with options is its file
/// pair alone; `o.key` may be dotted ("solver.cycle"), the params keep its leaf. The row's factory
/// reads it with param_value.
OptionSpec solver_param(OptionSpec o);
/// The value of the solver_param option `option` in `config`: the config's, else its default
/// (a config built in code holds only what it set).
nlohmann::json param_value(const SolverConfig& config, const OptionSpec& option);

/// The object ("solver", or "" at the top) and the key within it of a dotted key.
std::pair<std::string, std::string> split_key(const std::string& key);
/// The option of `options` whose key within its object is `leaf` ("cycles"), or nullptr.
const OptionSpec* find_option(const std::vector<OptionSpec>& options, const std::string& leaf);

/// Reads `option` from `reader` (its object's reader) into `config`, whose current value is the
/// default, with the reader's strict checks of type, range and allowed values.
void read_option(ConfigReader& reader, const OptionSpec& option, FlowConfig& config);

}  // namespace mcf
