#pragma once
// The triangle mesh value type every layer exchanges: plain Eigen arrays, no topology.
// OpenMesh is used for STL I/O and topology checks only (docs/design.md "Libraries";
// datasets/mesh_io.h).

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products are used everywhere meshes are

namespace mcf {

/// Vertex positions, one row per vertex (n x 3).
using Positions = Eigen::Matrix<double, Eigen::Dynamic, 3>;
/// Triangles as vertex indices, one row per face (m x 3), counter-clockwise seen from outside.
using Triangles = Eigen::Matrix<int, Eigen::Dynamic, 3>;

struct TriangleMesh {
  Positions vertices;
  Triangles faces;

  Eigen::Index num_vertices() const { return vertices.rows(); }
  Eigen::Index num_faces() const { return faces.rows(); }
};

}  // namespace mcf
