#include "bases/clip.h"
#include "bases/octree.h"

#include <gtest/gtest.h>

#include "test_meshes.h"

#include <cmath>

namespace {

using mcf::ClippedTriangle;
using mcf::GridCube;

// Sum of piece areas per source triangle must equal the triangle's area; every piece's centroid
// lies in its (closed) cell; returns the total piece area.
double check_pieces(const mcf::TriangleMesh& m, const GridCube& cube,
                    const std::vector<ClippedTriangle>& pieces) {
  std::vector<double> area(static_cast<std::size_t>(m.num_faces()), 0.0);
  const double h = cube.cell_size();
  int prev = -1;
  for (const auto& p : pieces) {
    EXPECT_GE(p.triangle, prev) << "pieces not in triangle order";
    prev = p.triangle;
    area[static_cast<std::size_t>(p.triangle)] += p.area();
    const auto ijk = mcf::grid_index(p.cell);
    const Eigen::Vector3d c = p.centroid();
    for (int a = 0; a < 3; ++a) {
      const double u = (c[a] - cube.origin[a]) / h;
      EXPECT_GE(u, ijk[a] - 1e-9) << "centroid outside its cell";
      EXPECT_LE(u, ijk[a] + 1 + 1e-9) << "centroid outside its cell";
      EXPECT_GE(ijk[a], 0);
      EXPECT_LT(ijk[a], cube.resolution());
      for (int v = 0; v < 3; ++v) {  // corners too (closed box, up to rounding)
        const double w = (p.corners[v][a] - cube.origin[a]) / h;
        EXPECT_GE(w, ijk[a] - 1e-9);
        EXPECT_LE(w, ijk[a] + 1 + 1e-9);
      }
    }
  }
  double total = 0.0;
  for (Eigen::Index f = 0; f < m.num_faces(); ++f) {
    const double a = test_face_area(m, f);
    EXPECT_NEAR(area[static_cast<std::size_t>(f)], a, 1e-12 * a + 1e-300) << "triangle " << f;
    total += area[static_cast<std::size_t>(f)];
  }
  return total;
}

TEST(Clip, RotatedSphereKeepsArea) {
  auto m = test_icosphere(3, 1.0);
  const Eigen::Matrix3d R = test_random_rotation(11);
  m.vertices = (m.vertices * R.transpose()).rowwise() + Eigen::RowVector3d(0.1, -0.2, 0.3);
  for (int depth : {4, 6}) {
    const GridCube cube = mcf::choose_cube(m, depth, mcf::OctreeCube::tight);
    const auto pieces = mcf::clip_mesh(m.vertices, m.faces, cube);
    EXPECT_GT(pieces.size(), static_cast<std::size_t>(m.num_faces()));
    const double total = check_pieces(m, cube, pieces);
    EXPECT_NEAR(total, test_mesh_area(m), 1e-12 * test_mesh_area(m));
  }
}

TEST(Clip, VerticesExactlyOnGridPlanes) {
  // Sphere in the unit cube with every vertex coordinate snapped to a grid plane of depth 5: all
  // vertices lie on three planes, many edges lie in planes.
  auto m = test_icosphere(3, 0.35, Eigen::Vector3d(0.5, 0.5, 0.5));
  const int depth = 5;
  const double h = 1.0 / 32.0;
  for (Eigen::Index v = 0; v < m.num_vertices(); ++v)
    for (int a = 0; a < 3; ++a) m.vertices(v, a) = std::round(m.vertices(v, a) / h) * h;
  const GridCube cube = mcf::choose_cube(m, depth, mcf::OctreeCube::unit);
  EXPECT_EQ(cube.side, 1.0);
  const auto pieces = mcf::clip_mesh(m.vertices, m.faces, cube);
  const double total = check_pieces(m, cube, pieces);
  EXPECT_NEAR(total, test_mesh_area(m), 1e-12 * test_mesh_area(m));
}

TEST(Clip, TrianglesInsideGridPlanesAreNotDoubled) {
  // The surface of the box [0.25,0.75]^3: every face lies in a grid plane (depth 4).
  mcf::TriangleMesh m;
  m.vertices.resize(8, 3);
  for (int c = 0; c < 8; ++c)
    m.vertices.row(c) << 0.25 + 0.5 * (c & 1), 0.25 + 0.5 * ((c >> 1) & 1),
        0.25 + 0.5 * ((c >> 2) & 1);
  m.faces.resize(12, 3);
  m.faces << 0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4, 2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4,
      6, 1, 3, 5, 3, 7, 5;
  const GridCube cube = mcf::choose_cube(m, 4, mcf::OctreeCube::unit);
  const auto pieces = mcf::clip_mesh(m.vertices, m.faces, cube);
  const double total = check_pieces(m, cube, pieces);
  EXPECT_NEAR(total, 1.5, 1e-14);
  // Each 1/16 x 1/16 face square of the 8x8 grid on each box face, split into triangles.
  EXPECT_GE(pieces.size(), static_cast<std::size_t>(6 * 64 * 2));
}

TEST(Clip, SingleTriangleSpanningManyCells) {
  mcf::TriangleMesh m;
  m.vertices.resize(3, 3);
  m.vertices << 0.01, 0.02, 0.03, 0.97, 0.11, 0.5, 0.3, 0.95, 0.9;
  m.faces.resize(1, 3);
  m.faces << 0, 1, 2;
  const GridCube cube = mcf::choose_cube(m, 6, mcf::OctreeCube::unit);
  const auto pieces = mcf::clip_mesh(m.vertices, m.faces, cube);
  EXPECT_GT(pieces.size(), 2000u);
  const double total = check_pieces(m, cube, pieces);
  EXPECT_NEAR(total, test_mesh_area(m), 1e-12 * test_mesh_area(m));
  // Original corners are kept exactly.
  int exact = 0;
  for (const auto& p : pieces)
    for (int v = 0; v < 3; ++v)
      for (int c = 0; c < 3; ++c)
        if (p.corner(v) == m.vertices.row(c).transpose()) ++exact;
  EXPECT_GE(exact, 3);
}

TEST(Clip, DegenerateTriangleGivesNoPieces) {
  std::vector<ClippedTriangle> out;
  GridCube cube;
  cube.depth = 5;
  mcf::clip_triangle({0.1, 0.1, 0.1}, {0.5, 0.5, 0.5}, {0.9, 0.9, 0.9}, 0, cube, out);
  EXPECT_TRUE(out.empty());
  mcf::clip_triangle({0.1, 0.1, 0.1}, {0.1, 0.1, 0.1}, {0.1, 0.1, 0.1}, 0, cube, out);
  EXPECT_TRUE(out.empty());
}

TEST(Clip, DeterministicAndEqualToSerial) {
  auto m = test_icosphere(3, 0.4, Eigen::Vector3d(0.5, 0.5, 0.5));
  const GridCube cube = mcf::choose_cube(m, 6, mcf::OctreeCube::automatic);
  const auto pieces = mcf::clip_mesh(m.vertices, m.faces, cube);
  std::vector<ClippedTriangle> serial;
  for (Eigen::Index f = 0; f < m.num_faces(); ++f)
    mcf::clip_triangle(
        m.vertices.row(m.faces(f, 0)).transpose(), m.vertices.row(m.faces(f, 1)).transpose(),
        m.vertices.row(m.faces(f, 2)).transpose(), static_cast<int>(f), cube, serial);
  ASSERT_EQ(pieces.size(), serial.size());
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    EXPECT_EQ(pieces[i].triangle, serial[i].triangle);
    EXPECT_EQ(pieces[i].cell, serial[i].cell);
    EXPECT_EQ(pieces[i].corner(0), serial[i].corner(0));
  }
}

}  // namespace
