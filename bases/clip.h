#pragma once
// Clipping of a triangle mesh to the finest grid cells (docs/design.md "The octree basis"): every
// triangle is split by the planes x = o_x + i h, y = o_y + j h, z = o_z + k h into convex pieces,
// one per cell, which are fan-triangulated.
//
// Robustness: the split of a convex polygon by a plane uses exact sign tests on the coordinate
// (points exactly on the plane go to both sides, a polygon lying in the plane goes to one side
// only, so no area is doubled); intersection points get the plane coordinate exactly and their
// other coordinates clamped between the edge's end points, so every piece lies in the closed box
// of its cell. Original vertices are kept bit-exactly. Fan triangles with area <= 1e-14 h^2
// (rounding slivers) are dropped; they cannot change the total area at the 1e-12 level.
// The piece's cell is the one it was cut into; its centroid lies in that (closed) cell.

#include "bases/octree.h"
#include "datasets/mesh.h"

#include <vector>

namespace mcf {

struct ClippedTriangle {
  double corners[3][3];  ///< corners[v][axis], world coordinates
  GridKey cell;          ///< finest cell (i,j,k) containing the piece
  int triangle;          ///< index of the source triangle

  Eigen::Vector3d corner(int v) const { return {corners[v][0], corners[v][1], corners[v][2]}; }
  Eigen::Vector3d centroid() const { return (corner(0) + corner(1) + corner(2)) / 3.0; }
  /// Unnormalised normal (p1-p0)x(p2-p0); its norm is twice the area.
  Eigen::Vector3d cross() const {
    const double u[3] = {corners[1][0] - corners[0][0], corners[1][1] - corners[0][1],
                         corners[1][2] - corners[0][2]};
    const double v[3] = {corners[2][0] - corners[0][0], corners[2][1] - corners[0][1],
                         corners[2][2] - corners[0][2]};
    return {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
  }
  double area() const { return 0.5 * cross().norm(); }
};

/// Appends the pieces of one triangle (a, b, c) to `out`, in a deterministic order.
void clip_triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                   int triangle, const GridCube& cube, std::vector<ClippedTriangle>& out);

/// Pieces of all faces, parallel over triangles (TBB); output is the per-triangle output
/// concatenated in triangle order (independent of the thread count).
std::vector<ClippedTriangle> clip_mesh(const Positions& vertices, const Triangles& faces,
                                       const GridCube& cube);

}  // namespace mcf
