// `mcfbench mesh-info SPEC`: the flags of loading, validating and describing a mesh
// (datasets/mesh_info.h).

#include "datasets/mesh_info.h"
#include "datasets/mesh_spec.h"
#include "tools/commands.h"

#include <cstdio>
#include <memory>

namespace mcf {

void add_mesh_info_command(CLI::App& app, std::function<int()>& run) {
  auto spec = std::make_shared<std::string>();
  auto out = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand("mesh-info",
                                     "Load and validate a mesh spec; print vertices, faces, "
                                     "boundary loops, components, genus, area as JSON.");
  cmd->footer("Mesh specs:\n" + mesh_spec_help());
  cmd->add_option("spec", *spec, "Mesh spec or file")->required();
  cmd->add_option(
      "--write", *out,
      "Also write the (generated / scaled / subdivided) mesh to this file (.off .ply .obj .stl)");
  cmd->callback([spec, out, &run] {
    run = [spec, out]() -> int {
      std::printf("%s\n", mesh_info(*spec, *out).dump(2).c_str());
      return 0;
    };
  });
}

}  // namespace mcf
