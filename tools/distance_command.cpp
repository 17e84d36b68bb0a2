// `mcfbench distance A B`: the flags of the Metro-style distance between two surfaces
// (harness/surface_distance.h).

#include "datasets/mesh_spec.h"
#include "harness/surface_distance.h"
#include "tools/commands.h"

#include <cstdio>
#include <memory>

namespace mcf {

void add_distance_command(CLI::App& app, std::function<int()>& run) {
  struct Args {
    std::string a, b;
    long long samples = 100000;
    std::uint64_t seed = 1;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd =
      app.add_subcommand("distance",
                         "Metro-style distance between two surfaces: uniform area sampling of "
                         "each, exact point-to-triangle "
                         "distance to the other through a BVH. Prints JSON {rms_forward, "
                         "max_forward, rms_backward, max_backward, "
                         "rms, max, samples} (forward: samples of A to B; max = Hausdorff).");
  cmd->footer(
      "A and B: an existing mesh file is read as is, NOT scaled into the unit cube (a flow's "
      "output is\n"
      "already in its flow's frame); anything else is a mesh spec, handled as everywhere else:\n" +
      mesh_spec_help());
  cmd->add_option("A", args->a, "First surface: file or mesh spec")->required();
  cmd->add_option("B", args->b, "Second surface: file or mesh spec")->required();
  cmd->add_option("--samples", args->samples, "Samples per surface")
      ->check(CLI::Range(1LL, 1000000000LL))
      ->capture_default_str();
  cmd->add_option("--seed", args->seed, "Random seed (same seed, same samples, same answer)")
      ->capture_default_str();
  cmd->callback([args, &run] {
    run = [args]() -> int {
      std::printf("%s\n",
                  surface_distance(args->a, args->b, args->samples, args->seed).dump(2).c_str());
      return 0;
    };
  });
}

}  // namespace mcf
