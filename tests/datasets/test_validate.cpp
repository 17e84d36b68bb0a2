#include "datasets/generators.h"
#include "datasets/validate.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <string>

namespace mcf {
namespace {

TriangleMesh two_triangles() {
  TriangleMesh m;
  m.vertices.resize(4, 3);
  m.vertices << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0;
  m.faces.resize(2, 3);
  m.faces << 0, 1, 2, 0, 2, 3;
  return m;
}

void expect_error(const TriangleMesh& m, const std::string& fragment) {
  try {
    validate_mesh(m, "mymesh");
    FAIL() << "no error, expected '" << fragment << "'";
  } catch (const MeshError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind("mymesh: ", 0), 0u) << msg;
    EXPECT_NE(msg.find(fragment), std::string::npos) << msg;
  }
}

TEST(Validate, SquareReport) {
  const MeshReport r = validate_mesh(two_triangles(), "square");
  EXPECT_EQ(r.vertices, 4);
  EXPECT_EQ(r.faces, 2);
  EXPECT_EQ(r.boundary_loops, 1);
  EXPECT_EQ(r.connected_components, 1);
  EXPECT_EQ(r.euler_characteristic, 1);
  EXPECT_EQ(r.genus, 0);
  EXPECT_EQ(r.misoriented_edges, 0);
  EXPECT_FALSE(r.closed());
  EXPECT_DOUBLE_EQ(r.area, 1.0);
}

TEST(Validate, Errors) {
  expect_error(TriangleMesh{}, "empty");
  TriangleMesh m = two_triangles();
  m.vertices(2, 1) = std::numeric_limits<double>::quiet_NaN();
  expect_error(m, "vertex 2");
  m = two_triangles();
  m.vertices(3, 0) = std::numeric_limits<double>::infinity();
  expect_error(m, "vertex 3");
  m = two_triangles();
  m.faces(1, 2) = 4;
  expect_error(m, "face 1 references vertex 4");
  m = two_triangles();
  m.faces(1, 2) = -1;
  expect_error(m, "face 1 references vertex -1");
  m = two_triangles();
  m.faces(1, 1) = 0;
  expect_error(m, "face 1 repeats");
  m = two_triangles();
  m.vertices.row(2) << 0.5, 0, 0;  // face 0 collinear
  expect_error(m, "face 0 is degenerate");
  m = two_triangles();
  m.vertices.row(2) << 0.5, 1e-6, 0;  // thin (area 5e-7) but well above 1e-14 * diag^2
  EXPECT_NO_THROW(validate_mesh(m, "thin"));
  m.vertices.row(2) << 0.5, 1e-16, 0;  // relative area 5e-17: degenerate
  expect_error(m, "degenerate");
}

TEST(Validate, NonManifoldEdge) {
  TriangleMesh m;
  m.vertices.resize(5, 3);
  m.vertices << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1;
  m.faces.resize(3, 3);
  m.faces << 0, 1, 2, 1, 0, 3, 0, 1, 4;
  expect_error(m, "non-manifold edge (0, 1)");
}

TEST(Validate, UnreferencedAndComponents) {
  // Two disjoint tetrahedra and one stray vertex.
  TriangleMesh m;
  m.vertices.resize(9, 3);
  m.vertices << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1,  //
      5, 0, 0, 6, 0, 0, 5, 1, 0, 5, 0, 1,            //
      9, 9, 9;
  m.faces.resize(8, 3);
  m.faces << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3,  //
      4, 6, 5, 4, 5, 7, 4, 7, 6, 5, 6, 7;
  const MeshReport r = validate_mesh(m, "two");
  EXPECT_EQ(r.unreferenced_vertices, 1);
  EXPECT_EQ(r.connected_components, 2);
  EXPECT_EQ(r.euler_characteristic, 4);
  EXPECT_EQ(r.genus, 0);
  EXPECT_TRUE(r.closed());
}

TEST(Validate, MisorientedEdgesAreCounted) {
  TriangleMesh m = two_triangles();
  m.faces.row(1) << 0, 3, 2;  // flipped
  EXPECT_EQ(validate_mesh(m, "flip").misoriented_edges, 1);
}

TEST(Validate, BoundaryVerticesAndArea) {
  const TriangleMesh cyl = make_open_cylinder(1.0, 2.0, 16, 4);
  const auto b = boundary_vertices(cyl);
  EXPECT_EQ(b.size(), 32u);
  for (int v : b) EXPECT_NEAR(std::abs(cyl.vertices(v, 2)), 1.0, 1e-12);
  EXPECT_TRUE(boundary_vertices(make_icosphere(1)).empty());
  EXPECT_DOUBLE_EQ(surface_area(two_triangles()), 1.0);
}

TEST(Validate, LargeMeshIsFast) {
  // ~1.3M faces: O(n log n) validation must stay around a second even in a slow build.
  const TriangleMesh m = make_icosphere(8);
  const auto t0 = std::chrono::steady_clock::now();
  const MeshReport r = validate_mesh(m, "big");
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(r.genus, 0);
  EXPECT_LT(s, 5.0);
}

}  // namespace
}  // namespace mcf
