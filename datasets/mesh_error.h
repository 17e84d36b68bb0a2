#pragma once
#include <stdexcept>
#include <string>

namespace mcf {

/// Any problem with a mesh input. The message always names the file (or mesh spec) and the
/// problem, e.g. "bunny.off: face 12 references vertex 9001 but the mesh has 800 vertices".
struct MeshError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace mcf
