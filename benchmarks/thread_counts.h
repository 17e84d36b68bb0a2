#pragma once
// The thread counts a micro-benchmark runs at: $MCFBENCH_THREADS, a comma-separated list such as
// "1,2,4,8,16" (0 = every core of the machine), when set; otherwise the benchmark's own default.
// The many-core scaling run (benchmarks/many_core.sh) sets it. Benchmarks are registered before
// main(), so the variable is read then; a malformed list stops the program with a message naming
// the variable (exit 2), before any benchmark runs.

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

namespace mcf {

inline std::vector<std::int64_t> bench_thread_counts(std::vector<std::int64_t> fallback) {
  const char* env = std::getenv("MCFBENCH_THREADS");
  if (env == nullptr || *env == '\0') return fallback;
  std::vector<std::int64_t> counts;
  const std::string list(env);
  std::size_t begin = 0;
  while (begin <= list.size()) {
    const std::size_t end = std::min(list.find(',', begin), list.size());
    const std::string item = list.substr(begin, end - begin);
    char* stop = nullptr;
    const long t = item.empty() ? -1 : std::strtol(item.c_str(), &stop, 10);
    if (item.empty() || *stop != '\0' || t < 0 || t > 4096) {
      std::fprintf(stderr,
                   "mcfbench_micro: MCFBENCH_THREADS=\"%s\": \"%s\" is not a thread count (a "
                   "comma-separated list of integers, 0 = all cores)\n",
                   env, item.c_str());
      std::exit(2);
    }
    counts.push_back(t == 0 ? std::int64_t(std::max(1u, std::thread::hardware_concurrency())) : t);
    begin = end + 1;
  }
  return counts;
}

}  // namespace mcf
