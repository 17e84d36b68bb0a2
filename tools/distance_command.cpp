// `mcfbench distance A B`: Metro-style distance between two surfaces (bench/metrics.h).

#include "bench/metrics.h"
#include "datasets/mesh_io.h"
#include "datasets/mesh_spec.h"
#include "tools/commands.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>

namespace mcf {

namespace {
/// An existing file is read as is (no unit-cube scaling: comparing a flow's output with its
/// reference must not rescale either); anything else is a mesh spec (generators, cgal:..., @faces).
TriangleMesh load_surface(const std::string& name) {
  std::error_code ec;
  if (std::filesystem::is_regular_file(name, ec)) return read_mesh(name);
  return load_mesh_spec(name).mesh;
}
}  // namespace

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
      const TriangleMesh a = load_surface(args->a), b = load_surface(args->b);
      const auto start = std::chrono::steady_clock::now();
      const MeshDistance d = mesh_distance(a, b, args->samples, args->seed);
      const double seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const nlohmann::json j = {{"a", args->a},
                                {"b", args->b},
                                {"rms_forward", d.rms_forward},
                                {"max_forward", d.max_forward},
                                {"rms_backward", d.rms_backward},
                                {"max_backward", d.max_backward},
                                {"rms", d.rms},
                                {"max", d.max},
                                {"samples", d.samples},
                                {"seed", args->seed},
                                {"seconds", seconds}};
      std::printf("%s\n", j.dump(2).c_str());
      return 0;
    };
  });
}

}  // namespace mcf
