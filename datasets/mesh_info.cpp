#include "datasets/mesh_info.h"

#include "datasets/mesh_io.h"
#include "datasets/mesh_spec.h"

namespace mcf {

nlohmann::json mesh_description(const MeshSource& m) {
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
                      {"bbox_max", {hi.x(), hi.y(), hi.z()}},
                      {"reoriented_faces", r.reoriented_faces},
                      {"repaired_faces", r.repaired_faces},
                      {"degenerate_faces", r.degenerate_faces}};
  if (!m.notes.empty()) j["notes"] = m.notes;
  if (m.sphere_radius) j["sphere_radius"] = *m.sphere_radius;
  if (m.cylinder_radius) j["cylinder_radius"] = *m.cylinder_radius;
  return j;
}

nlohmann::json mesh_info(const std::string& spec, const std::string& write_to,
                         const MeshLoadOptions& options) {
  const MeshSource m = load_mesh_spec(spec, options);
  nlohmann::json j = mesh_description(m);
  // Written before the report is printed: a write that fails (an unknown extension, a missing
  // folder) exits non-zero with nothing on stdout, not after a complete-looking report.
  if (!write_to.empty()) write_mesh(write_to, m.mesh, true, FaceCheck::trusted);
  return j;
}

}  // namespace mcf
