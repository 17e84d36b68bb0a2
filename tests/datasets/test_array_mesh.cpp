// mesh_source_from_arrays: a mesh given as arrays goes through a file's checks (corners,
// orientation, half-edge insertion, zero-area faces, validation), with errors naming the arrays
// and the face, and keeps its frame (a file is scaled into the unit cube).

#include "datasets/mesh_spec.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

namespace mcf {
namespace {

/// A tetrahedron of side about 20, away from the unit cube, faces outward.
TriangleMesh tetrahedron() {
  TriangleMesh m;
  m.vertices.resize(4, 3);
  m.vertices << 10, 10, 10, 30, 10, 10, 10, 30, 10, 10, 10, 30;
  m.faces.resize(4, 3);
  m.faces << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3;
  return m;
}

std::string error_of(const TriangleMesh& m, const MeshLoadOptions& options = {}) {
  try {
    mesh_source_from_arrays(m, "arrays", options);
  } catch (const MeshError& e) {
    return e.what();
  }
  return "";
}

TEST(ArrayMesh, KeepsItsFrameAndReportsAsAFileDoes) {
  const TriangleMesh m = tetrahedron();
  const MeshSource s = mesh_source_from_arrays(m, "arrays");
  EXPECT_EQ(s.mesh.vertices, m.vertices);  // not scaled into the unit cube
  EXPECT_EQ(s.mesh.faces, m.faces);
  EXPECT_EQ(s.spec, "arrays");
  EXPECT_EQ(s.kind, "arrays");
  EXPECT_FALSE(s.analytic);
  EXPECT_EQ(s.report.vertices, 4);
  EXPECT_EQ(s.report.faces, 4);
  EXPECT_EQ(s.report.genus, 0);
  EXPECT_TRUE(s.report.closed());
  EXPECT_EQ(s.report.reoriented_faces, 0);
}

TEST(ArrayMesh, FacesOfMixedOrientationAreReorientedAndNoted) {
  TriangleMesh m = tetrahedron();
  std::swap(m.faces(3, 1), m.faces(3, 2));  // one face inward
  const MeshSource s = mesh_source_from_arrays(m, "arrays");
  EXPECT_EQ(s.report.reoriented_faces, 1);
  ASSERT_EQ(s.notes.size(), 1u);
  EXPECT_NE(s.notes[0].find("reoriented 1 of 4 faces"), std::string::npos);
  EXPECT_GT(test::signed_volume(s.mesh), 0);
}

TEST(ArrayMesh, BadArraysAreRefusedNamingTheFace) {
  TriangleMesh range = tetrahedron();
  range.faces(2, 1) = 4;
  EXPECT_NE(error_of(range).find("arrays: face 2 references vertex 4 but the mesh has 4 vertices"),
            std::string::npos)
      << error_of(range);
  TriangleMesh negative = tetrahedron();
  negative.faces(1, 0) = -1;
  EXPECT_NE(error_of(negative).find("face 1 references vertex -1"), std::string::npos);
  TriangleMesh repeated = tetrahedron();
  repeated.faces(0, 2) = repeated.faces(0, 0);
  EXPECT_NE(error_of(repeated).find("face 0 repeats vertex 0"), std::string::npos);
  TriangleMesh nan = tetrahedron();
  nan.vertices(1, 2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(error_of(nan).find("arrays"), std::string::npos) << error_of(nan);
  TriangleMesh three = tetrahedron();  // a fifth face on edge (0, 1), which has two already
  three.vertices.conservativeResize(5, 3);
  three.vertices.row(4) << 20, 0, 20;
  three.faces.conservativeResize(5, 3);
  three.faces.row(4) << 0, 1, 4;
  EXPECT_NE(error_of(three).find("non-manifold mesh: face 4"), std::string::npos)
      << error_of(three);
  EXPECT_NE(error_of(TriangleMesh{}), "");
}

TEST(ArrayMesh, ZeroAreaFacesAreTreatedAsTheOptionsSay) {
  TriangleMesh m = tetrahedron();
  m.vertices.row(3) << 20, 10, 10;  // on edge (0, 1): face (0, 1, 3) collapses to a line
  EXPECT_NE(error_of(m).find("arrays"), std::string::npos) << error_of(m);
  MeshLoadOptions keep;
  keep.degenerate = DegenerateFaces::keep;
  EXPECT_GT(mesh_source_from_arrays(m, "arrays", keep).report.degenerate_faces, 0);
}

}  // namespace
}  // namespace mcf
