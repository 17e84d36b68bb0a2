#pragma once
// Where a result came from: git commit, CPU, cores, threads, library versions, peak memory.

#include <nlohmann/json.hpp>

namespace mcf {

/// {"commit", "cpu", "cores", "threads", "hostname", "libraries": {...}, "build": {...}}
nlohmann::json environment_json(int threads);
/// Peak resident set size of this process (getrusage), in bytes.
long long peak_memory_bytes();

}  // namespace mcf
