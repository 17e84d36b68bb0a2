#include "flows/option_spec.h"

#include "flows/config_reader.h"

namespace mcf {

void read_option(ConfigReader& reader, const OptionSpec& option, FlowConfig& config) {
  const nlohmann::json current = option.get(config);
  switch (option.type) {
    case OptionType::string:
      option.set(config, reader.get_string(option.key, current.get<std::string>()));
      break;
    case OptionType::integer:
      option.set(config, reader.get_integer(option.key, current.get<long long>(),
                                            (long long)option.min, (long long)option.max));
      break;
    case OptionType::number:
      option.set(config,
                 reader.get_number(option.key, current.get<double>(), option.min, option.max));
      break;
    case OptionType::boolean:
      option.set(config, reader.get_bool(option.key, current.get<bool>()));
      break;
  }
}

}  // namespace mcf
