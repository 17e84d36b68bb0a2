// Options into a flow config: every setting goes to its config key and the whole config through
// flow_config_from_json, the reader `mcfbench flow`'s flags and experiment configs go through, so
// the library takes exactly the keys, values and combinations the command line takes.

#include "api/detail.h"
#include "mcfbench/flow.h"

#include "config/config_reader.h"
#include "config/config_schema.h"
#include "harness/json_path.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <map>
#include <vector>

namespace mcfbench {
namespace detail {
namespace {

using nlohmann::json;

/// Edit distance, for "did you mean".
std::size_t distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] != b[j - 1])});
      diagonal = up;
    }
  }
  return row[b.size()];
}

std::string dashed(std::string name) {
  std::replace(name.begin(), name.end(), '_', '-');
  return name;
}

/// Where a setting goes: the option whose flag it names, or the config key it is.
struct Target {
  const mcf::OptionSpec* flag = nullptr;  ///< set for a flag's name
  std::string key;                        ///< the config key
};

Target target_of(const std::string& name, const std::string& source) {
  const std::vector<mcf::OptionSpec>& schema = mcf::flow_config_schema();
  if (name.find('.') == std::string::npos) {
    const std::string flag = "--" + dashed(name);
    for (const mcf::OptionSpec& o : schema)
      if (o.flag == flag) return {&o, o.key};
  }
  // A config key ("solver.cycles", "extrapolate"): a leaf of the schema.
  for (const mcf::OptionSpec& o : schema)
    if (o.key == name) return {nullptr, o.key};
  std::string best;
  std::size_t best_distance = 3;  // suggest only near misses
  for (const mcf::OptionSpec& o : schema) {
    for (const std::string& candidate :
         {o.flag.empty() ? std::string() : o.flag.substr(2), o.key}) {
      if (candidate.empty()) continue;
      const std::size_t d = std::min(distance(dashed(name), candidate), distance(name, candidate));
      if (d < best_distance) best_distance = d, best = candidate;
    }
  }
  std::replace(best.begin(), best.end(), '-', '_');
  throw InputError(source + ": unknown option \"" + name + "\"" +
                   (best.empty() ? "" : " (did you mean \"" + best + "\"?)") +
                   "; the options are those of `mcfbench flow` (docs/flow.md#flow)");
}

json json_of(const Value& v) {
  return std::visit([](const auto& x) { return json(x); }, v.value);
}

/// "SOURCE: KEY: what" from the reader, with the name the caller gave the key beside it.
std::string named_error(const std::string& message, const std::string& source,
                        const std::map<std::string, std::string>& given) {
  const std::string head = source + ": ";
  if (message.rfind(head, 0) != 0) return message;
  const std::size_t end = message.find(": ", head.size());
  if (end == std::string::npos) return message;
  const std::string key = message.substr(head.size(), end - head.size());
  const auto it = given.find(key);
  if (it == given.end() || it->second == key) return message;
  return head + it->second + " (" + key + ")" + message.substr(end);
}

}  // namespace

mcf::FlowConfig flow_config(const Options& options, const std::optional<std::string>& mesh,
                            bool stand_in) {
  const std::string& source = options.name;
  json j = json::object();
  if (!options.config_file.empty()) {
    if (!options.config_json.empty())
      throw InputError(source + ": a config file and a config text given; give one");
    j = translated([&] { return mcf::read_config_file(options.config_file); });
  } else if (!options.config_json.empty()) {
    try {
      j = json::parse(options.config_json);
    } catch (const json::exception& e) {
      throw InputError(source + ": config: " + e.what());
    }
  }
  if (!j.is_object()) throw InputError(source + ": config: expected a JSON object");
  std::map<std::string, std::string> given;  // config key -> the name a setting gave it
  for (const auto& [name, value] : options.settings) {
    const Target t = target_of(name, source);
    json v = json_of(value);
    if (t.flag && t.flag->flag_kind != mcf::FlagKind::value) {
      if (!v.is_boolean())
        throw InputError(source + ": " + name + ": expected true or false, got " + v.dump());
      v = t.flag->flag_kind == mcf::FlagKind::set_true ? v.get<bool>() : !v.get<bool>();
    } else if (t.flag && t.flag->parse_flag && v.is_string()) {
      try {
        v = t.flag->parse_flag(v.get<std::string>());
      } catch (const std::invalid_argument& e) {
        throw InputError(source + ": " + name + ": " + e.what());
      }
    }
    mcf::set_json_path(j, t.key, v);
    given[t.key] = name;
  }
  if (mesh) {
    const json* named = mcf::json_at_path(j, "mesh");
    if (named && !stand_in)
      throw InputError(source + ": mesh: " + named->dump() + " named beside the mesh " + *mesh +
                       " given; give one");
    if (!named) j["mesh"] = *mesh;
  }
  try {
    return mcf::flow_config_from_json(j, source);
  } catch (const mcf::ConfigError& e) {
    throw InputError(named_error(e.what(), source, given));
  } catch (const std::invalid_argument& e) {
    throw InputError(named_error(e.what(), source, given));
  }
}

}  // namespace detail

std::vector<OptionInfo> flow_options() {
  std::vector<OptionInfo> out;
  for (const mcf::OptionSpec& o : mcf::flow_config_schema()) {
    if (o.flag.empty()) continue;
    OptionInfo info;
    info.flag = o.flag;
    info.name = o.flag.substr(2);
    std::replace(info.name.begin(), info.name.end(), '-', '_');
    info.key = o.key;
    info.values = mcf::option_values(o);
    info.fallback = mcf::option_default(o);
    info.help = o.help;
    info.switch_only = o.flag_kind != mcf::FlagKind::value;
    if (o.flag_kind == mcf::FlagKind::set_false) info.help += " (true sets " + o.key + " to false)";
    out.push_back(std::move(info));
  }
  return out;
}

}  // namespace mcfbench
