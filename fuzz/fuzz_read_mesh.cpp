// read_mesh on an arbitrary file of one format (MCF_FUZZ_EXTENSION, e.g. ".off": one target per
// reader, built from this file by fuzz/CMakeLists.txt), then validate_mesh on what it read (as
// load_mesh_spec does for a file): each may refuse the input with MeshError; any other exception, a
// crash, a sanitizer report, a hang or unbounded memory is a finding.

#include "datasets/mesh_io.h"
#include "datasets/validate.h"
#include "fuzz/fuzz_file.h"

#include <cstddef>
#include <cstdint>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = mcf::fuzz::input_file(data, size, MCF_FUZZ_EXTENSION);
  try {
    const mcf::TriangleMesh mesh = mcf::read_mesh(path);
    mcf::validate_mesh(mesh, path);
  } catch (const mcf::MeshError&) {
  }
  return 0;
}
