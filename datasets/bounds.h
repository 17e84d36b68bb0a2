#pragma once
// The bounding box of the surface: of the vertices some face uses. A vertex no face uses (scans
// and exported files have them; mesh-info counts them) is not part of the surface, and one stray
// vertex far away would otherwise shrink the model when it is fitted into the unit cube and
// coarsen its octree grid by as many levels.

#include "datasets/mesh.h"

#include <limits>
#include <vector>

namespace mcf {

struct Bounds {
  Eigen::RowVector3d lo, hi;
  Eigen::RowVector3d extent() const { return hi - lo; }
};

/// Bounds of the vertices the faces use; of every vertex when there are no faces. Face indices
/// must be valid (read_mesh and the generators guarantee it).
inline Bounds surface_bounds(const TriangleMesh& mesh) {
  if (mesh.num_faces() == 0) return {mesh.vertices.colwise().minCoeff(), mesh.vertices.colwise().maxCoeff()};
  std::vector<char> used(static_cast<std::size_t>(mesh.num_vertices()), 0);
  for (Eigen::Index f = 0; f < mesh.num_faces(); ++f)
    for (int c = 0; c < 3; ++c) used[static_cast<std::size_t>(mesh.faces(f, c))] = 1;
  Bounds b{Eigen::RowVector3d::Constant(std::numeric_limits<double>::infinity()),
           Eigen::RowVector3d::Constant(-std::numeric_limits<double>::infinity())};
  for (Eigen::Index v = 0; v < mesh.num_vertices(); ++v)
    if (used[static_cast<std::size_t>(v)]) {
      b.lo = b.lo.cwiseMin(mesh.vertices.row(v));
      b.hi = b.hi.cwiseMax(mesh.vertices.row(v));
    }
  return b;
}

}  // namespace mcf
