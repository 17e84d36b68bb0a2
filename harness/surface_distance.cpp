#include "harness/surface_distance.h"

#include "datasets/mesh_io.h"
#include "datasets/mesh_spec.h"
#include "harness/metrics.h"

#include <chrono>
#include <filesystem>

namespace mcf {
namespace {

TriangleMesh load_surface(const std::string& name) {
  std::error_code ec;
  if (std::filesystem::is_regular_file(name, ec)) return read_mesh(name);
  return load_mesh_spec(name).mesh;
}

}  // namespace

nlohmann::json surface_distance(const std::string& a, const std::string& b, long long samples,
                                std::uint64_t seed) {
  const TriangleMesh mesh_a = load_surface(a), mesh_b = load_surface(b);
  const auto start = std::chrono::steady_clock::now();
  const MeshDistance d = mesh_distance(mesh_a, mesh_b, samples, seed);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return {{"a", a},
          {"b", b},
          {"rms_forward", d.rms_forward},
          {"max_forward", d.max_forward},
          {"rms_backward", d.rms_backward},
          {"max_backward", d.max_backward},
          {"rms", d.rms},
          {"max", d.max},
          {"samples", d.samples},
          {"seed", seed},
          {"seconds", seconds}};
}

}  // namespace mcf
