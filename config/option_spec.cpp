#include "config/option_spec.h"

#include "config/config_reader.h"

namespace mcf {

OptionSpec option(std::string key, OptionType type, nlohmann::json fallback, std::string flag,
                  std::string help) {
  OptionSpec o;
  o.key = std::move(key);
  o.type = type;
  o.fallback = std::move(fallback);
  o.flag = std::move(flag);
  o.help = std::move(help);
  return o;
}

OptionSpec ranged(OptionSpec o, double min, double max) {
  o.min = min;
  o.max = max;
  return o;
}

OptionSpec solver_param(OptionSpec o) {
  const std::string leaf = split_key(o.key).second;
  const nlohmann::json fallback = o.fallback;
  o.get = [leaf, fallback](const FlowConfig& c) {
    const auto it = c.solver.params.find(leaf);
    return it != c.solver.params.end() ? *it : fallback;
  };
  o.set = [leaf](FlowConfig& c, const nlohmann::json& v) { c.solver.params[leaf] = v; };
  return o;
}

nlohmann::json param_value(const SolverConfig& config, const OptionSpec& option) {
  const auto it = config.params.find(split_key(option.key).second);
  return it != config.params.end() ? *it : option.fallback;
}

std::pair<std::string, std::string> split_key(const std::string& key) {
  const std::size_t dot = key.rfind('.');
  if (dot == std::string::npos) return {"", key};
  return {key.substr(0, dot), key.substr(dot + 1)};
}

const OptionSpec* find_option(const std::vector<OptionSpec>& options, const std::string& leaf) {
  for (const OptionSpec& o : options)
    if (split_key(o.key).second == leaf) return &o;
  return nullptr;
}

void read_option(ConfigReader& reader, const OptionSpec& option, FlowConfig& config) {
  const std::string leaf = split_key(option.key).second;
  const nlohmann::json current = option.get(config);
  switch (option.type) {
    case OptionType::string: {
      std::vector<std::string> allowed;
      if (option.choices)
        for (const Choice& c : option.choices()) allowed.push_back(c.first);
      option.set(config, reader.get_string(leaf, current.get<std::string>(), allowed));
      break;
    }
    case OptionType::integer:
      option.set(config, reader.get_integer(leaf, current.get<long long>(),
                                            static_cast<long long>(option.min),
                                            static_cast<long long>(option.max)));
      break;
    case OptionType::number:
      option.set(config, reader.get_number(leaf, current.get<double>(), option.min, option.max));
      break;
    case OptionType::boolean:
      option.set(config, reader.get_bool(leaf, current.get<bool>()));
      break;
  }
  if (option.after) option.after(config, reader, leaf);
}

}  // namespace mcf
