// read_mesh on an arbitrary .stl file, then validate_mesh on what it read (as load_mesh_spec
// does for a file): each may refuse the input with MeshError; any other exception, a crash, a
// sanitizer report, a hang or unbounded memory is a finding.

#include "datasets/mesh_io.h"
#include "datasets/validate.h"
#include "fuzz/fuzz_file.h"

#include <cstddef>
#include <cstdint>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = mcf::fuzz::input_file(data, size, ".stl");
  try {
    const mcf::TriangleMesh mesh = mcf::read_mesh(path);
    mcf::validate_mesh(mesh, path);
  } catch (const mcf::MeshError&) {
  }
  return 0;
}
