#pragma once
// Mesh validation: fatal problems throw MeshError naming the mesh and the problem; the rest is
// reported (docs/flow.md "Validation").

#include "datasets/mesh.h"
#include "datasets/mesh_error.h"

#include <array>
#include <string>
#include <vector>

namespace mcf {

struct MeshReport {
  long long vertices = 0;
  long long faces = 0;
  long long unreferenced_vertices = 0;
  long long boundary_loops = 0;
  long long connected_components = 0;
  long long euler_characteristic = 0;
  long long genus = 0;  ///< sum over components of (2 - χ_c - b_c) / 2
  double area = 0.0;
  /// Interior edges whose two faces traverse them in the same direction (0 for a consistently
  /// oriented mesh). Reported, not fatal: some real models are not orientable-consistent.
  long long misoriented_edges = 0;
  bool closed() const { return boundary_loops == 0; }
};

/// Throws MeshError("<name>: <problem>") when the mesh is empty, has NaN/inf coordinates, face
/// indices out of range, repeated indices in a face, degenerate (zero-area) faces or
/// non-manifold edges (an edge shared by more than two faces). Otherwise returns the report.
MeshReport validate_mesh(const TriangleMesh& mesh, const std::string& name);

/// Unreferenced vertices do not count in χ or components. Boundary loops are the connected
/// components of the boundary-edge graph (two holes touching at one vertex count as one).

/// Edges with exactly one incident face, as vertex pairs (smaller index first), sorted.
std::vector<std::array<int, 2>> boundary_edges(const Triangles& faces);

/// Vertices on a boundary loop (sorted, unique).
std::vector<int> boundary_vertices(const TriangleMesh& mesh);

/// Total surface area.
double surface_area(const TriangleMesh& mesh);

}  // namespace mcf
