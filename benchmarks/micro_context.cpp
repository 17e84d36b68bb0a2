// The machine and commit of a mcfbench_micro run, in Google Benchmark's JSON context as
// "mcfbench_environment" (the environment object of a result.json, harness/environment.h), so that
// `mcfbench history add` (benchmarks/run_micro.sh) files micro-benchmark results under the same
// machine identity and commit as the study results.

#include "harness/environment.h"

#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <exception>

namespace {

// Runs before benchmark_main's main(), which writes the context after this has added to it.
// threads = 0: the benchmarks choose their own thread counts; the identity records what the
// machine allows, as a flow left at its default does.
const bool kContextAdded = [] {
  try {
    benchmark::AddCustomContext("mcfbench_environment", mcf::environment_json(0).dump());
  } catch (const std::exception& e) {  // e.g. a malformed $MCFBENCH_PLANTED_SLOWDOWN
    std::fprintf(stderr, "mcfbench_micro: %s\n", e.what());
    std::exit(2);
  }
  return true;
}();

}  // namespace
