// An experiment config file, read as `mcfbench run` reads it (load_experiment_config: the strict
// JSON reading, then parsing and expanding the matrix), full and quick. ConfigError is the only
// refusal allowed; any other exception, a crash, a sanitizer report, a hang or unbounded memory
// is a finding. Nothing is run: a cell's mesh spec is a string here.

#include "config/config_reader.h"
#include "fuzz/fuzz_file.h"
#include "harness/experiment_config.h"

#include <cstddef>
#include <cstdint>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = mcf::fuzz::input_file(data, size, ".json");
  for (const bool quick : {false, true}) {
    try {
      mcf::load_experiment_config(path, quick);
    } catch (const mcf::ConfigError&) {
    }
  }
  return 0;
}
