#pragma once
// The vertices some face uses, and the surface's bounding box over them. A vertex no face uses
// (scans and exported files have them; mesh-info counts them as unreferenced_vertices) is not
// part of the surface: one stray vertex far away would otherwise shrink the model when it is
// fitted into the unit cube and coarsen its octree grid by as many levels.

#include "datasets/mesh.h"

#include <limits>
#include <vector>

namespace mcf {

/// referenced[v] == 1 when a face uses vertex v (of num_vertices). Face indices must be valid
/// (read_mesh and the generators guarantee it; validate_mesh checks it first).
inline std::vector<char> referenced_vertices(Eigen::Index num_vertices, const Triangles& faces) {
  std::vector<char> referenced(static_cast<std::size_t>(num_vertices), 0);
  for (Eigen::Index f = 0; f < faces.rows(); ++f)
    for (int c = 0; c < 3; ++c) referenced[static_cast<std::size_t>(faces(f, c))] = 1;
  return referenced;
}

struct Bounds {
  Eigen::RowVector3d lo, hi;
  Eigen::RowVector3d extent() const { return hi - lo; }
};

/// Bounds of the vertices marked in `referenced` (referenced_vertices).
inline Bounds bounds_of(const Positions& vertices, const std::vector<char>& referenced) {
  Bounds b{Eigen::RowVector3d::Constant(std::numeric_limits<double>::infinity()),
           Eigen::RowVector3d::Constant(-std::numeric_limits<double>::infinity())};
  for (Eigen::Index v = 0; v < vertices.rows(); ++v)
    if (referenced[static_cast<std::size_t>(v)]) {
      b.lo = b.lo.cwiseMin(vertices.row(v));
      b.hi = b.hi.cwiseMax(vertices.row(v));
    }
  return b;
}

/// Bounds of the vertices the faces use; of every vertex when there are no faces.
inline Bounds surface_bounds(const TriangleMesh& mesh) {
  if (mesh.num_faces() == 0)
    return {mesh.vertices.colwise().minCoeff(), mesh.vertices.colwise().maxCoeff()};
  return bounds_of(mesh.vertices, referenced_vertices(mesh.num_vertices(), mesh.faces));
}

}  // namespace mcf
