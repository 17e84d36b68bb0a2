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
  /// Zero-area faces kept (ValidateOptions::keep_degenerate); 0 otherwise.
  long long degenerate_faces = 0;
  /// Faces the reader reversed to orient the surface consistently (read_mesh's ReadReport).
  long long reoriented_faces = 0;
  /// Zero-area faces removed by the opt-in repair (repair_degenerate_faces).
  long long repaired_faces = 0;
  bool closed() const { return boundary_loops == 0; }
};

struct ValidateOptions {
  /// Count zero-area faces in MeshReport::degenerate_faces instead of refusing them (for a use
  /// that needs no face's cotangents, such as the octree basis's integration over the surface).
  bool keep_degenerate = false;
  /// Appended to the refusal of a zero-area face: what the caller offers instead.
  std::string degenerate_hint;
};

/// Throws MeshError("<name>: <problem>") when the mesh is empty, has NaN/inf coordinates, face
/// indices out of range, repeated indices in a face, degenerate (zero-area) faces (unless
/// options.keep_degenerate) or non-manifold edges (an edge shared by more than two faces).
/// Otherwise returns the report.
MeshReport validate_mesh(const TriangleMesh& mesh, const std::string& name,
                         const ValidateOptions& options = {});

/// The faces validate_mesh calls degenerate: area zero, or at most 1e-14 times the squared
/// diagonal of the surface's bounding box (relative, since the studies mix unit-cube models and
/// large analytic shapes). Face indices must be valid.
std::vector<Eigen::Index> degenerate_faces(const TriangleMesh& mesh);

/// The area at or below which a face of this mesh is degenerate (degenerate_faces).
double degenerate_area(const TriangleMesh& mesh);

/// Unreferenced vertices do not count in χ or components. Boundary loops are the connected
/// components of the boundary-edge graph (two holes touching at one vertex count as one).

/// Edges with exactly one incident face, as vertex pairs (smaller index first), sorted.
std::vector<std::array<int, 2>> boundary_edges(const Triangles& faces);

/// Vertices on a boundary loop (sorted, unique).
std::vector<int> boundary_vertices(const TriangleMesh& mesh);

/// Total surface area.
double surface_area(const TriangleMesh& mesh);

}  // namespace mcf
