// `mcfbench mesh-info SPEC` (or `--mesh SPEC`, as every other subcommand names its mesh): the
// flags of loading, validating and describing a mesh (datasets/mesh_info.h).

#include "datasets/mesh_info.h"
#include "datasets/mesh_spec.h"
#include "tools/commands.h"

#include <cstdio>
#include <memory>

namespace mcf {
namespace {

struct MeshInfoArgs {
  std::string spec, mesh, out;
  bool repair_degenerate = false, keep_degenerate = false;
};

}  // namespace

void add_mesh_info_command(CLI::App& app, std::function<int()>& run) {
  auto a = std::make_shared<MeshInfoArgs>();
  CLI::App* cmd = app.add_subcommand("mesh-info",
                                     "Load and validate a mesh spec; print vertices, faces, "
                                     "boundary loops, components, genus, area as JSON.");
  cmd->footer("Mesh specs:\n" + mesh_spec_help());
  CLI::Option* positional = cmd->add_option("spec", a->spec, "Mesh spec or file");
  CLI::Option* named = cmd->add_option("--mesh", a->mesh,
                                       "Mesh spec or file (the same as SPEC, as `flow` names it)");
  positional->excludes(named);
  cmd->add_option(
      "--write", a->out,
      "Also write the (generated / scaled / subdivided) mesh to this file (.off .ply .obj .stl)");
  CLI::Option* repair = cmd->add_flag(
      "--repair-degenerate", a->repair_degenerate,
      "Collapse zero-area faces (as `flow --repair-degenerate` does) instead of refusing them");
  cmd->add_flag("--keep-degenerate", a->keep_degenerate,
                "Count zero-area faces instead of refusing them (as the octree basis does)")
      ->excludes(repair);
  cmd->callback([a, &run] {
    if (a->spec.empty() && a->mesh.empty()) throw CLI::RequiredError("a mesh: SPEC or --mesh SPEC");
    run = [a]() -> int {
      const std::string& spec = a->spec.empty() ? a->mesh : a->spec;
      MeshLoadOptions options;
      if (a->repair_degenerate) options.degenerate = DegenerateFaces::repair;
      if (a->keep_degenerate) options.degenerate = DegenerateFaces::keep;
      options.degenerate_hint =
          ": --repair-degenerate removes zero-area faces, --keep-degenerate counts them";
      const nlohmann::json info = mesh_info(spec, a->out, options);
      for (const auto& note : info.value("notes", nlohmann::json::array()))
        std::fprintf(stderr, "mcfbench mesh-info: %s: %s\n", spec.c_str(),
                     note.get<std::string>().c_str());
      std::printf("%s\n", info.dump(2).c_str());
      return 0;
    };
  });
}

}  // namespace mcf
