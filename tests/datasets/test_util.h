#pragma once
// Small helpers shared by the datasets tests (and TempDir of the core tests).

#include "../core/temp_dir.h"
#include "datasets/mesh.h"

#include <Eigen/Geometry>

#include <gtest/gtest.h>

namespace mcf::test {

/// Signed volume enclosed by a closed mesh: positive when faces are oriented outward.
inline double signed_volume(const TriangleMesh& m) {
  double v = 0;
  for (Eigen::Index f = 0; f < m.num_faces(); ++f) {
    const Eigen::Vector3d a = m.vertices.row(m.faces(f, 0)), b = m.vertices.row(m.faces(f, 1)),
                          c = m.vertices.row(m.faces(f, 2));
    v += a.dot(b.cross(c)) / 6.0;
  }
  return v;
}

/// Two triangles are the same face when they are equal up to a cyclic rotation.
inline bool same_face(const Eigen::RowVector3i& a, const Eigen::RowVector3i& b) {
  for (int r = 0; r < 3; ++r)
    if (a(0) == b(r) && a(1) == b((r + 1) % 3) && a(2) == b((r + 2) % 3)) return true;
  return false;
}

}  // namespace mcf::test
