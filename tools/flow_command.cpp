// `mcfbench flow`: the flags of one flow, written to OUT/result.json and OUT/final.ply (+ frames)
// by harness/flow_folder.h. Every flag but --config, --max-memory and --out is an option of the
// flow config's schema (config/config_schema.h), made from it with its help.

#include "config/config_schema.h"
#include "datasets/mesh_spec.h"
#include "harness/flow_folder.h"
#include "tools/commands.h"

#include <deque>
#include <memory>
#include <stdexcept>

namespace mcf {
namespace {

/// A flag's value as CLI11 fills it, in the type its option has.
struct FlagValue {
  std::string text;
  int integer = 0;
  double number = 0;
  bool on = false;
};

struct FlowArgs {
  std::string config_file, out, max_memory;
  /// One per option of flow_config_schema(), in its order (a deque: CLI11 holds references).
  std::deque<FlagValue> values;
};

void add_flow_options(CLI::App& cmd, FlowArgs& args) {
  cmd.add_option("--config", args.config_file,
                 "JSON flow config (same keys as result.json's \"config\"); flags override it");
  for (const OptionSpec& o : flow_config_schema()) {
    FlagValue& v = args.values.emplace_back();
    if (o.flag.empty()) continue;
    const std::string help = option_flag_help(o);
    if (o.flag_kind != FlagKind::value)
      cmd.add_flag(o.flag, v.on, help);
    else if (o.parse_flag || o.type == OptionType::string)
      cmd.add_option(o.flag, v.text, help);
    else if (o.type == OptionType::integer)
      cmd.add_option(o.flag, v.integer, help);
    else
      cmd.add_option(o.flag, v.number, help);
  }
  cmd.add_option("--max-memory", args.max_memory,
                 "Refuse a flow whose estimated peak memory exceeds SIZE (8G, 512M; none: no "
                 "check; default: the memory available now)");
  cmd.add_option("--out", args.out, "Output folder")->required();
}

/// The settings of the flags given on the command line, in the flow config's keys; --config FILE
/// supplies the rest.
FlowRequest flow_request(const CLI::App& cmd, const FlowArgs& args) {
  FlowRequest r;
  r.config_file = args.config_file;
  r.out = args.out;
  r.max_memory = args.max_memory;
  const std::vector<OptionSpec>& schema = flow_config_schema();
  for (std::size_t i = 0; i < schema.size(); ++i) {
    const OptionSpec& o = schema[i];
    if (o.flag.empty() || cmd.count(o.flag) == 0) continue;
    const FlagValue& v = args.values[i];
    nlohmann::json value;
    if (o.flag_kind != FlagKind::value) {
      value = o.flag_kind == FlagKind::set_true ? v.on : !v.on;
    } else if (o.parse_flag) {
      try {
        value = o.parse_flag(v.text);
      } catch (const std::invalid_argument& e) {
        throw CLI::ValidationError(o.flag, e.what());
      }
    } else if (o.type == OptionType::string) {
      value = v.text;
    } else if (o.type == OptionType::integer) {
      value = v.integer;
    } else {
      value = v.number;
    }
    r.settings.emplace_back(o.key, value);
  }
  return r;
}

}  // namespace

void add_flow_command(CLI::App& app, std::function<int()>& run) {
  auto args = std::make_shared<FlowArgs>();
  CLI::App* cmd = app.add_subcommand(
      "flow", "Run one flow and write OUT/result.json, OUT/final.ply (and frames).");
  cmd->footer("Mesh specs:\n" + mesh_spec_help() +
              "\nExample:\n  mcfbench flow --mesh sphere:vertices=2000 --flow mcf --basis hat "
              "--solver cholmod "
              "--dt 1e-3 --steps 20 --out out/sphere\n");
  add_flow_options(*cmd, *args);

  run = nullptr;
  cmd->callback([cmd, args, &run] {
    run = [cmd, args]() -> int { return run_flow_into_folder(flow_request(*cmd, *args)); };
  });
}

}  // namespace mcf
