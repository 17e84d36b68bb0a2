// The opt-in repair of zero-area faces: a flat cap is flipped away where its longest edge has a
// face on the other side (no vertex moves) and collapsed onto that edge where not, coincident
// corners merge into one vertex; vertices keep their indices; what the repair leaves is a mesh
// that validates, and load_mesh_spec reports it. Without the repair, zero-area faces are refused
// (with the caller's hint) or, when asked, kept and counted.

#include "datasets/mesh_io.h"
#include "datasets/mesh_spec.h"
#include "datasets/repair.h"
#include "datasets/validate.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <string>

namespace mcf {
namespace {

using test::TempDir;

// A unit square of two triangles whose bottom edge carries a flat cap: vertex 4 is the midpoint
// of the edge (0, 1) and the face (0, 1, 4) has zero area.
const char* kSquareWithCap =
    "OFF\n5 4 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 0 0\n"
    "3 0 4 2\n3 4 1 2\n3 0 2 3\n3 0 1 4\n";

TEST(Repair, AFlatCapCollapsesOntoItsLongestEdge) {
  TempDir dir;
  TriangleMesh m = read_mesh(dir.write("cap.off", kSquareWithCap));
  ASSERT_EQ(degenerate_faces(m), (std::vector<Eigen::Index>{3}));
  const DegenerateRepair r = repair_degenerate_faces(m);
  EXPECT_EQ(r.degenerate_faces, 1);
  EXPECT_EQ(r.removed_faces, 2);  // the cap and its neighbour across the collapsed edge
  EXPECT_EQ(r.merged_vertices, 1);
  EXPECT_EQ(m.num_vertices(), 5);  // vertex 4 stays, unreferenced, where it was
  ASSERT_EQ(m.num_faces(), 2);
  EXPECT_EQ(m.faces.row(0), Eigen::RowVector3i(0, 1, 2));
  EXPECT_EQ(m.faces.row(1), Eigen::RowVector3i(0, 2, 3));
  const MeshReport v = validate_mesh(m, "repaired");
  EXPECT_EQ(v.unreferenced_vertices, 1);
  EXPECT_DOUBLE_EQ(v.area, 1.0);
}

TEST(Repair, AFlatCapBesideAFaceIsFlippedAwayMovingNothing) {
  // A diamond 0 3 1 2 whose diagonal (0, 1) carries vertex 4 at its midpoint: below it two
  // triangles meet at 4, above it one triangle spans the whole diagonal, and the zero-area cap
  // (1, 0, 4) fills the T between them.
  TriangleMesh m;
  m.vertices.resize(5, 3);
  m.vertices << 0, 0, 0, 2, 0, 0, 1, 1, 0, 1, -1, 0, 1, 0, 0;
  m.faces.resize(4, 3);
  m.faces << 0, 1, 2, 4, 0, 3, 1, 4, 3, 1, 0, 4;
  check_half_edge_faces(m, "diamond");
  const Positions before = m.vertices;
  const DegenerateRepair r = repair_degenerate_faces(m);
  EXPECT_EQ(r.degenerate_faces, 1);
  EXPECT_EQ(r.flipped_faces, 1);
  EXPECT_EQ(r.removed_faces, 0);
  EXPECT_EQ(r.merged_vertices, 0);
  EXPECT_EQ(m.vertices, before);
  ASSERT_EQ(m.num_faces(), 4);
  // The top triangle, split at 4; the bottom ones as they were.
  EXPECT_EQ(m.faces.row(0), Eigen::RowVector3i(4, 1, 2));
  EXPECT_EQ(m.faces.row(3), Eigen::RowVector3i(0, 4, 2));
  EXPECT_EQ(m.faces.row(1), Eigen::RowVector3i(4, 0, 3));
  EXPECT_EQ(m.faces.row(2), Eigen::RowVector3i(1, 4, 3));
  check_half_edge_faces(m, "flipped");
  const MeshReport v = validate_mesh(m, "flipped");
  EXPECT_DOUBLE_EQ(v.area, 2.0);
  EXPECT_EQ(v.unreferenced_vertices, 0);
  EXPECT_EQ(v.misoriented_edges, 0);
}

TEST(Repair, CoincidentCornersMergeIntoOneVertex) {
  // An octahedron whose vertex 5 is split in two at the same point (5 and 6), joined by two
  // zero-area slivers (5, 6, 1) and (6, 5, 3).
  TriangleMesh m;
  m.vertices.resize(7, 3);
  m.vertices << 1, 0, 0, 0, 1, 0, -1, 0, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, -1;
  m.faces.resize(10, 3);
  m.faces << 0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4,  // the top
      1, 0, 5, 2, 1, 6, 3, 2, 6, 0, 3, 5,         // the bottom, around 5 and 6
      5, 6, 1, 6, 5, 3;                           // the slivers
  check_half_edge_faces(m, "split octahedron");
  EXPECT_EQ(degenerate_faces(m).size(), 2u);
  const DegenerateRepair r = repair_degenerate_faces(m);
  EXPECT_EQ(r.degenerate_faces, 2);  // one collapse of the edge (5, 6) removes both slivers
  EXPECT_EQ(r.merged_vertices, 1);
  EXPECT_EQ(r.removed_faces, 2);
  EXPECT_EQ(m.num_faces(), 8);
  EXPECT_TRUE(degenerate_faces(m).empty());
  check_half_edge_faces(m, "repaired");
  const MeshReport v = validate_mesh(m, "repaired");
  EXPECT_EQ(v.boundary_loops, 0);
  EXPECT_EQ(v.genus, 0);
  EXPECT_EQ(v.unreferenced_vertices, 1);  // vertex 6, merged into 5
}

TEST(Repair, LoadMeshSpecRefusesKeepsOrCollapsesAsAsked) {
  TempDir dir;
  const std::string path = dir.write("cap.off", kSquareWithCap);
  MeshLoadOptions refuse;
  refuse.degenerate_hint = ": try the other option";
  try {
    load_mesh_spec(path, refuse);
    FAIL() << "a zero-area face was accepted";
  } catch (const MeshError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("face 3 is degenerate (area 0"), std::string::npos) << msg;
    EXPECT_NE(msg.find(": try the other option"), std::string::npos) << msg;
  }
  MeshLoadOptions keep;
  keep.degenerate = DegenerateFaces::keep;
  const MeshSource kept = load_mesh_spec(path, keep);
  EXPECT_EQ(kept.report.degenerate_faces, 1);
  EXPECT_EQ(kept.report.faces, 4);
  ASSERT_EQ(kept.notes.size(), 1u);
  EXPECT_NE(kept.notes[0].find("kept 1 zero-area face"), std::string::npos) << kept.notes[0];
  MeshLoadOptions collapse;
  collapse.degenerate = DegenerateFaces::repair;
  const MeshSource repaired = load_mesh_spec(path, collapse);
  EXPECT_EQ(repaired.report.repaired_faces, 1);
  EXPECT_EQ(repaired.report.degenerate_faces, 0);
  EXPECT_EQ(repaired.report.faces, 2);
  ASSERT_EQ(repaired.notes.size(), 1u);
  EXPECT_NE(repaired.notes[0].find("removed 1 zero-area face"), std::string::npos)
      << repaired.notes[0];
  // A mesh without zero-area faces is loaded the same either way, with nothing to say.
  const std::string good =
      dir.write("square.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n");
  const MeshSource plain = load_mesh_spec(good), fixed = load_mesh_spec(good, collapse);
  EXPECT_EQ(plain.mesh.faces, fixed.mesh.faces);
  EXPECT_TRUE(fixed.notes.empty());
}

}  // namespace
}  // namespace mcf
