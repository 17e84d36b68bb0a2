// A mesh spec string: parse_mesh_spec, then load_mesh_spec where the spec is a small generated
// mesh. MeshError is the only refusal allowed; any other exception, a crash, a sanitizer report,
// a hang or unbounded memory is a finding.
//
// A spec may rightly ask for up to 2e8 faces (the parser's limit), which no fuzz run can build
// every few milliseconds: this target builds only specs whose parsed size (the generator's
// estimate and @faces) is at most kMaxFuzzFaces, and checks that a generator never makes more
// faces than its estimate said. Files and cgal models are parsed only, never read: the fuzzer
// would otherwise read whatever path it makes up, and extract the catalogue.

#include "datasets/mesh_spec.h"

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace {
constexpr double kMaxFuzzFaces = 20'000;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string spec(reinterpret_cast<const char*>(data), size);
  try {
    const mcf::MeshSpecRequest r = mcf::parse_mesh_spec(spec);
    if (r.kind == "file" || r.kind == "cgal") return 0;
    if (r.generated_faces > kMaxFuzzFaces || r.target_faces > kMaxFuzzFaces) return 0;
    const mcf::MeshSource src = mcf::load_mesh_spec(spec);
    if (r.target_faces == 0 && src.mesh.num_faces() > r.generated_faces) {
      std::fprintf(stderr, "'%s' made %lld faces, more than its estimate %g\n", spec.c_str(),
                   static_cast<long long>(src.mesh.num_faces()), r.generated_faces);
      std::abort();
    }
  } catch (const mcf::MeshError&) {
  }
  return 0;
}
