#include "harness/cell_hash.h"

#include <cstdio>

namespace mcf {

std::uint64_t fnv1a64(const void* data, std::size_t size, std::uint64_t seed) {
  const auto* p = static_cast<const unsigned char*>(data);
  std::uint64_t h = seed;
  for (std::size_t i = 0; i < size; ++i) {
    h ^= p[i];
    h *= 0x100000001b3ULL;
  }
  return h;
}

std::uint64_t fnv1a64(const std::string& s, std::uint64_t seed) {
  return fnv1a64(s.data(), s.size(), seed);
}

std::string hex16(std::uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

std::string mesh_fingerprint(const TriangleMesh& mesh) {
  // Sizes first so that (V, F) splits of the same byte stream cannot collide.
  const long long sizes[2] = {mesh.num_vertices(), mesh.num_faces()};
  std::uint64_t h = fnv1a64(sizes, sizeof sizes);
  h = fnv1a64(mesh.vertices.data(), std::size_t(mesh.vertices.size()) * sizeof(double), h);
  h = fnv1a64(mesh.faces.data(), std::size_t(mesh.faces.size()) * sizeof(int), h);
  return hex16(h);
}

std::string cell_key(const nlohmann::json& full_config, int repetition,
                     const std::string& mesh_fp) {
  // nlohmann::json objects are std::map-backed: dump() is already sorted and canonical.
  return hex16(fnv1a64(full_config.dump() + "\nrepetition=" + std::to_string(repetition) +
                       "\nmesh=" + mesh_fp));
}

std::string cell_hash(const std::string& key, const std::string& code_version) {
  return hex16(fnv1a64(key + "\ncode=" + code_version));
}

}  // namespace mcf
