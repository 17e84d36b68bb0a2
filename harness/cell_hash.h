#pragma once
// Names of result files. A cell's *key* identifies what was computed (canonical config with
// defaults filled, repetition, the input mesh's bytes) and matches cells across commits in
// `compare`; its *hash* adds the code version, so a new commit never reuses an old result and
// two commits' results can live in one folder.

#include "datasets/mesh.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <string>

namespace mcf {

/// 64-bit FNV-1a over bytes, continuing from `seed` (so data can be hashed piecewise).
std::uint64_t fnv1a64(const void* data, std::size_t size,
                      std::uint64_t seed = 0xcbf29ce484222325ULL);
std::uint64_t fnv1a64(const std::string& s, std::uint64_t seed = 0xcbf29ce484222325ULL);
/// 16 lowercase hex digits.
std::string hex16(std::uint64_t v);

/// Fingerprint of the loaded mesh: vertex coordinates and face indices as stored (16 hex), so a
/// changed generator or an edited model file changes every dependent key.
std::string mesh_fingerprint(const TriangleMesh& mesh);

/// Key without code version: canonical dump (sorted keys) of the full config + repetition +
/// mesh fingerprint.
std::string cell_key(const nlohmann::json& full_config, int repetition,
                     const std::string& mesh_fingerprint);
/// The file name stem: the key plus the code version (git commit).
std::string cell_hash(const std::string& key, const std::string& code_version);

}  // namespace mcf
