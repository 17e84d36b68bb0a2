// `mcfbench mesh-info SPEC`: load, validate and describe a mesh.

#include "datasets/mesh_io.h"
#include "datasets/mesh_spec.h"
#include "tools/commands.h"

#include <nlohmann/json.hpp>

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
      const MeshSource m = load_mesh_spec(*spec);
      const MeshReport& r = m.report;
      const Eigen::Vector3d lo = m.mesh.vertices.colwise().minCoeff(),
                            hi = m.mesh.vertices.colwise().maxCoeff();
      nlohmann::json j = {{"spec", m.spec},
                          {"kind", m.kind},
                          {"analytic", m.analytic},
                          {"vertices", r.vertices},
                          {"faces", r.faces},
                          {"unreferenced_vertices", r.unreferenced_vertices},
                          {"boundary_loops", r.boundary_loops},
                          {"connected_components", r.connected_components},
                          {"euler_characteristic", r.euler_characteristic},
                          {"genus", r.genus},
                          {"area", r.area},
                          {"bbox_min", {lo.x(), lo.y(), lo.z()}},
                          {"bbox_max", {hi.x(), hi.y(), hi.z()}}};
      if (m.sphere_radius) j["sphere_radius"] = *m.sphere_radius;
      if (m.cylinder_radius) j["cylinder_radius"] = *m.cylinder_radius;
      // Written before the report is printed: a --write that fails (an unknown extension, a
      // missing folder) exits non-zero with nothing on stdout, not after a complete-looking report.
      if (!out->empty()) write_mesh(*out, m.mesh, true, FaceCheck::trusted);
      std::printf("%s\n", j.dump(2).c_str());
      return 0;
    };
  });
}

}  // namespace mcf
