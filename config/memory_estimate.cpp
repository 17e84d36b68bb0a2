#include "config/memory_estimate.h"

#include "config/basis_registry.h"
#include "config/solver_registry.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace mcf {
std::string format_gib(double bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f GiB", bytes / double(1ull << 30));
  return text;
}

nlohmann::json MemoryEstimate::to_json() const {
  return {
      {"bytes", total()},           {"resident_bytes", resident_bytes}, {"mesh_bytes", mesh_bytes},
      {"basis_bytes", basis_bytes}, {"solver_bytes", solver_bytes},     {"dimension", dimension},
      {"vertices", vertices},       {"lower_bound", lower_bound}};
}

std::string MemoryEstimate::describe(const FlowConfig& config) const {
  char sizes[96];
  if (lower_bound)
    std::snprintf(sizes, sizeof sizes, "%.3g vertices; the octree not counted", vertices);
  else
    std::snprintf(sizes, sizeof sizes, "%.3g unknowns", dimension);
  std::string what =
      format_gib(total()) + (lower_bound ? " at least" : "") + " (" + config.basis + " basis";
  if (const BasisRow& basis = basis_row(config.basis); basis.describe)
    what += basis.describe(config);
  return what + ", " + config.solver.name + ": " + sizes + ")";
}

FlowSizes spec_sizes(const MeshSpecRequest& request) {
  FlowSizes s;
  s.faces = std::max(request.generated_faces, double(request.target_faces));
  s.vertices = s.faces / 2;
  return s;
}

FlowSizes mesh_sizes(const FlowConfig& config, const TriangleMesh& mesh, bool analytic) {
  FlowSizes s;
  s.exact = true;
  const double split = config.octree.refine_input ? 4.0 : 1.0;
  s.faces = double(mesh.faces.rows()) * split;
  // A 1-to-4 split adds one vertex per edge: about 3/2 per face.
  s.vertices = double(mesh.vertices.rows()) + (split - 1.0) / 2.0 * double(mesh.faces.rows());
  if (const BasisRow& basis = basis_row(config.basis); basis.size)
    basis.size(config, mesh, analytic, s);
  return s;
}

MemoryEstimate estimate_flow_memory(const FlowConfig& config, const FlowSizes& sizes,
                                    double resident_bytes) {
  MemoryEstimate e;
  e.resident_bytes = resident_bytes;
  e.vertices = sizes.vertices;
  const BasisRow& basis = basis_row(config.basis);
  const BasisMemory share = basis.memory(config, sizes);
  e.mesh_bytes = share.mesh_bytes;
  e.basis_bytes = share.basis_bytes;
  e.dimension = share.dimension;
  e.lower_bound = share.lower_bound;
  if (e.lower_bound) return e;
  SystemFigures system = basis.system;
  system.dimension = e.dimension;
  e.solver_bytes = solver_row(config.solver.name).memory(config.solver, system);
  return e;
}

}  // namespace mcf
