#pragma once
// Where a result came from: git commit, CPU, cores, threads, library versions, peak memory.

#include <nlohmann/json.hpp>

namespace mcf {

/// {"commit", "cpu", "cores", "threads", "hostname", "libraries": {...}, "build": {...}}
/// "threads" is the parallelism the flow had: the request (0 = all) capped at the cores TBB uses.
nlohmann::json environment_json(int threads);
/// Peak resident set size of this process (getrusage), in bytes.
long long peak_memory_bytes();

}  // namespace mcf
