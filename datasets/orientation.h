#pragma once
// Consistent orientation of a face list: a manifold surface whose faces are listed with mixed
// orientation (some clockwise, some counter-clockwise) is the same surface, and a half-edge mesh
// holds it once its faces agree. orient_faces makes them agree by a breadth-first walk over
// edge-adjacent faces (as CGAL's orient_polygon_soup does), or says why no orientation exists:
// an edge in three or more faces (non-manifold), or a component that cannot be oriented at all
// (non-orientable: a Möbius strip, a Klein bottle).

#include "datasets/mesh.h"

#include <array>
#include <vector>

namespace mcf {

struct OrientationResult {
  enum class Problem {
    none,
    /// `edge` is in three or more faces; `faces` are the first three that use it, in face order
    /// (the third is the first face a half-edge mesh cannot add).
    non_manifold_edge,
    /// The component of `faces[0]` is non-orientable: the walk reached `faces[1]` across `edge`
    /// from `faces[0]` and needed it the other way round from the one it already had.
    non_orientable,
  };
  Problem problem = Problem::none;
  std::array<int, 2> edge{-1, -1};  ///< the edge of the problem (smaller vertex first)
  std::vector<Eigen::Index> faces;  ///< the faces of the problem (above)
  long long reoriented = 0;         ///< faces whose corner order was reversed
};

/// Reverses the corner order (a, b, c) -> (a, c, b) of the faces that disagree with their
/// edge-adjacent neighbours, component by component (components joined through edges; faces that
/// meet at a vertex only are oriented apart). In each component the orientation of the most faces
/// is kept (that of its first face on a tie), so a consistently oriented mesh is never changed.
/// Faces must have distinct corners in range. On a problem the faces are left as they were and
/// the result says what it is; the caller names it in its own numbering.
OrientationResult orient_faces(Triangles& faces);

}  // namespace mcf
