#pragma once
// Where a result came from: git commit, CPU, cores, threads, library versions, peak memory, and
// the CPU time the hypervisor took away while it ran.

#include <nlohmann/json.hpp>

#include <string>

namespace mcf {

/// {"commit", "cpu", "cores", "threads", "blas_threads", "hostname", "libraries": {...},
/// "build": {...}}. "threads" is the parallelism the flow had: the request (0 = all) capped at the
/// cores TBB uses; "blas_threads" the OpenBLAS threads it ran CHOLMOD with (result
/// "solver_settings.blas_threads"), the same as "threads" where not given; "planted_slowdown" and
/// "planted_phase" only when $MCFBENCH_PLANTED_SLOWDOWN slowed the steps or their updates on
/// purpose (flows/planted_slowdown.h; throws as that does on a malformed value).
nlohmann::json environment_json(int threads, int blas_threads = 0);
/// environment_json for a result that may hold "solver_settings.blas_threads".
nlohmann::json environment_json(int threads, const nlohmann::json& result);
/// The source tree the binary was built from (its reports/ and harness/configs/), as CMake saw it.
std::string source_dir();
/// Peak resident set size of this process (getrusage), in bytes.
long long peak_memory_bytes();

/// CPU time the hypervisor gave to other guests while this one wanted to run ("steal", the
/// eighth value of /proc/stat's aggregate `cpu` line), summed over all CPUs, in seconds since
/// boot; -1 where the kernel does not report it. The difference over a run says how much of a
/// slow run the host took as CPU time; noise from shared caches and memory bandwidth does not
/// show here.
double cpu_steal_seconds();
/// cpu_steal_seconds() now minus `before` (an earlier reading); -1 where either is unknown.
double cpu_steal_seconds_since(double before);
/// The steal field of /proc/stat's first line `text` at `ticks_per_second` (USER_HZ), in seconds;
/// -1 if the line is not an aggregate `cpu` line with at least eight values.
double steal_seconds_from_proc_stat(const std::string& text, long ticks_per_second);

}  // namespace mcf
