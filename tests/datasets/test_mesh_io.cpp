#include "datasets/generators.h"
#include "datasets/mesh_io.h"
#include "datasets/mesh_spec.h"
#include "datasets/validate.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <numeric>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

namespace mcf {
namespace {

using test::TempDir;

// Reading and validating, as every user of a file does (load_mesh_spec does both).
void load_checked(const std::string& path) {
  validate_mesh(read_mesh(path), path);
}

// Expects a MeshError whose message names the file (its base name at least).
void expect_error_naming(const std::string& path, const std::string& fragment = "") {
  try {
    load_checked(path);
    FAIL() << "no MeshError for " << path;
  } catch (const MeshError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(std::filesystem::path(path).filename().string()), std::string::npos) << msg;
    if (!fragment.empty()) {
      EXPECT_NE(msg.find(fragment), std::string::npos) << msg;
    }
  }
  // The spec loader must report the same problem with the file name too.
  try {
    load_mesh_spec(path);
    FAIL() << "load_mesh_spec accepted " << path;
  } catch (const MeshError& e) {
    EXPECT_NE(std::string(e.what()).find(std::filesystem::path(path).filename().string()),
              std::string::npos)
        << e.what();
  }
}

const char* kTetraOff =
    "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";

TEST(MeshIo, ReadsValidOff) {
  TempDir dir;
  const auto path = dir.write("tetra.off", kTetraOff);
  const TriangleMesh m = read_mesh(path);
  ASSERT_EQ(m.num_vertices(), 4);
  ASSERT_EQ(m.num_faces(), 4);
  EXPECT_EQ(m.vertices.row(3), Eigen::RowVector3d(0, 0, 1));  // vertex order kept
  EXPECT_TRUE(test::same_face(m.faces.row(1), Eigen::RowVector3i(0, 1, 3)));
  const MeshReport r = validate_mesh(m, path);
  EXPECT_TRUE(r.closed());
  EXPECT_EQ(r.genus, 0);
  EXPECT_EQ(r.misoriented_edges, 0);
  EXPECT_GT(test::signed_volume(m), 0);
}

// Geomview's keyword prefixes: colours and normals after the coordinates are ignored, 4OFF's
// homogeneous w divides the point (reading its first three numbers would scale the tetrahedron
// by 2), nOFF's dimension comes before the counts.
TEST(MeshIo, OffKeywordPrefixes) {
  TempDir dir;
  const std::string faces = "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
  const Eigen::RowVector3d last(0, 0, 1);
  {
    const TriangleMesh m = read_mesh(dir.write(
        "c.off",
        "COFF\n4 4 0\n0 0 0 1 0 0 1\n1 0 0 1 0 0 1\n0 1 0 1 0 0 1\n0 0 1 1 0 0 1\n" + faces));
    EXPECT_EQ(m.vertices.row(3), last);
  }
  {
    const TriangleMesh m = read_mesh(
        dir.write("h.off", "4OFF\n4 4 0\n0 0 0 2\n2 0 0 2\n0 3 0 3\n0 0 -0.5 -0.5\n" + faces));
    EXPECT_EQ(m.vertices.row(1), Eigen::RowVector3d(1, 0, 0));
    EXPECT_EQ(m.vertices.row(2), Eigen::RowVector3d(0, 1, 0));
    EXPECT_EQ(m.vertices.row(3), last);
  }
  for (const char* header :
       {"nOFF\n3\n4 4 0\n", "nOFF 3 4 4 0\n", "CnOFF\n3 4 4 0\n", "STOFF\n4 4 0\n"}) {
    SCOPED_TRACE(header);
    const TriangleMesh m =
        read_mesh(dir.write("n.off", std::string(header) + "0 0 0\n1 0 0\n0 1 0\n0 0 1\n" + faces));
    ASSERT_EQ(m.num_vertices(), 4);
    ASSERT_EQ(m.num_faces(), 4);
    EXPECT_EQ(m.vertices.row(3), last);
  }
  expect_error_naming(
      dir.write("n4.off", "nOFF\n4\n4 4 0\n0 0 0 0\n1 0 0 0\n0 1 0 0\n0 0 1 0\n" + faces),
      "dimension 4");
  expect_error_naming(
      dir.write("w0.off", "4OFF\n4 4 0\n0 0 0 1\n1 0 0 1\n0 1 0 1\n0 0 1 0\n" + faces),
      "vertex 3 has homogeneous coordinate w = 0");
  expect_error_naming(dir.write("w.off", "4OFF\n4 4 0\n0 0 0 1\n1 0 0 1\n0 1 0 1\n0 0 1\n" + faces),
                      "vertex 3: cannot parse");
  expect_error_naming(dir.write("x.off", "XOFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n" + faces),
                      "[ST][C][N][4][n]OFF");
  expect_error_naming(dir.write("s.off", "SOFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n" + faces),
                      "[ST][C][N][4][n]OFF");
}

TEST(MeshIo, MissingFile) {
  expect_error_naming("/nonexistent_dir_xyz/missing_mesh.off", "no such file");
}

TEST(MeshIo, GarbageText) {
  TempDir dir;
  expect_error_naming(dir.write("garbage.off", "hello world\nthis is not a mesh\n"));
  expect_error_naming(dir.write("garbage.ply", "hello world\nthis is not a mesh\n"));
  expect_error_naming(dir.write("garbage.obj", "hello world\nthis is not a mesh\n"));
  expect_error_naming(dir.write("garbage.stl", "hello world\nthis is not a mesh\n"));
}

TEST(MeshIo, EmptyFiles) {
  TempDir dir;
  expect_error_naming(dir.write("empty.off", ""), "empty");
  expect_error_naming(dir.write("empty.obj", ""), "empty");
  expect_error_naming(dir.write("empty.ply", ""), "empty");
  // A header announcing no faces parses, but is an empty mesh.
  expect_error_naming(dir.write("nofaces.off", "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n"), "empty");
}

TEST(MeshIo, NanCoordinate) {
  TempDir dir;
  expect_error_naming(dir.write("nan.off", "OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n"),
                      "vertex 1");
  expect_error_naming(dir.write("nan.obj", "v 0 0 0\nv 1 0 0\nv 0 inf 0\nf 1 2 3\n"), "vertex 2");
}

TEST(MeshIo, IndexOutOfRange) {
  TempDir dir;
  expect_error_naming(dir.write("range.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n"),
                      "vertex 7");
  expect_error_naming(dir.write("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"),
                      "line 4: face refers to vertex 9");
  expect_error_naming(dir.write("zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"),
                      "line 4: face corner '0'");
  expect_error_naming(dir.write("back.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n"),
                      "face corner '-4'");
  // Found by fuzzing: an index below LLONG_MIN saturates there, whose negation overflowed.
  expect_error_naming(
      dir.write("huge.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -99999999999999999999999\n"),
      "face corner '-99999999999999999999999'");
  // Relative (negative) and textured/normal forms of valid indices still load.
  EXPECT_EQ(read_mesh(dir.write("ok.obj",
                                "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nf -3/1/1 2//1 3/1\n"))
                .num_faces(),
            1);
  expect_error_naming(
      dir.write("range.ply",
                "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 9\n"));
}

TEST(MeshIo, ZeroAreaFace) {
  TempDir dir;
  // Three collinear points.
  expect_error_naming(dir.write("flat.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n2 0 0\n3 0 1 2\n"),
                      "degenerate");
  expect_error_naming(dir.write("flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n"), "degenerate");
}

TEST(MeshIo, NonManifoldEdge) {
  TempDir dir;
  // Edge (0,1) is shared by three triangles.
  const std::string verts = "0 0 0\n1 0 0\n0 1 0\n0 -1 0\n0 0 1\n";
  // The error names the first face that cannot be added and its edge, as the file numbers them.
  expect_error_naming(dir.write("fin.off", "OFF\n5 3 0\n" + verts + "3 0 1 2\n3 1 0 3\n3 0 1 4\n"),
                      "non-manifold mesh: face 2 (vertices 0, 1, 4) cannot be added: its edge (0, "
                      "1) already has a face");
  expect_error_naming(dir.write("fin.obj",
                                "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\n"
                                "f 1 2 3\nf 2 1 4\nf 1 2 5\n"),
                      "the face on line 8 (vertices 1, 2, 5) cannot be added: its edge (1, 2)");
  expect_error_naming(dir.write("fin.stl",
                                "solid fin\n"
                                "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 "
                                "0\nvertex 0 1 0\nendloop\nendfacet\n"
                                "facet normal 0 0 1\nouter loop\nvertex 1 0 0\nvertex 0 0 "
                                "0\nvertex 0 -1 0\nendloop\nendfacet\n"
                                "facet normal 0 1 0\nouter loop\nvertex 0 0 0\nvertex 1 0 "
                                "0\nvertex 0 0 1\nendloop\nendfacet\n"
                                "endsolid fin\n"),
                      "non-manifold");
  expect_error_naming(
      dir.write("fin.ply",
                "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\n"
                "property float z\nelement face 3\nproperty list uchar int vertex_indices\n"
                "end_header\n" +
                    verts + "3 0 1 2\n3 1 0 3\n3 0 1 4\n"),
      "face 2 (vertices 0, 1, 4)");
}

TEST(MeshIo, InconsistentlyOrientedFacesAreOriented) {
  TempDir dir;
  // Both triangles run along 0 -> 1: a half-edge mesh cannot hold them as listed (nor can the
  // flows), so the second is reversed to agree with the first.
  const std::string path =
      dir.write("flip.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n0 -1 0\n3 0 1 2\n3 0 1 3\n");
  ReadReport report;
  const TriangleMesh m = read_mesh(path, &report);
  EXPECT_EQ(report.reoriented_faces, 1);
  EXPECT_EQ(m.faces.row(0), Eigen::RowVector3i(0, 1, 2));
  EXPECT_EQ(m.faces.row(1), Eigen::RowVector3i(0, 3, 1));
  EXPECT_EQ(validate_mesh(m, path).misoriented_edges, 0);
}

TEST(MeshIo, NonManifoldVertex) {
  TempDir dir;
  // Two closed tetrahedra sharing vertex 0: once the first is closed, vertex 0 has no free side.
  const std::string off =
      "OFF\n7 8 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n-1 0 0\n0 -1 0\n0 0 -1\n"
      "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n"
      "3 0 4 5\n3 0 5 6\n3 0 6 4\n3 4 6 5\n";
  expect_error_naming(
      dir.write("pinch.off", off),
      "face 4 (vertices 0, 4, 5) cannot be added: its vertex 0 is already surrounded");
}

TEST(MeshIo, OpenFansMeetingAtAVertexLoad) {
  TempDir dir;
  // A bow tie: two triangles sharing only vertex 0, which stays on the boundary of both.
  const auto path = dir.write(
      "bowtie.off", "OFF\n5 2 0\n0 0 0\n1 0 0\n1 1 0\n-1 0 0\n-1 -1 0\n3 0 1 2\n3 0 3 4\n");
  const MeshReport r = validate_mesh(read_mesh(path), path);
  EXPECT_EQ(r.faces, 2);
  EXPECT_EQ(r.boundary_loops, 1);  // the two holes touch at vertex 0 (validate.h)
}

TEST(MeshIo, NonManifoldPolygonNamesItsFan) {
  TempDir dir;
  // The quad 0 1 4 5 is fanned into (0 1 4) and (0 4 5); the first is a third face on the edge
  // (0, 1), which two triangles hold already.
  expect_error_naming(dir.write("quadfin.off",
                                "OFF\n6 3 0\n0 0 0\n1 0 0\n0 1 0\n0 -1 0\n1 -1 0\n0 0 1\n"
                                "3 0 1 2\n3 1 0 3\n4 0 1 4 5\n"),
                      "triangle 1 of 2 fanned from face 2 (vertices 0, 1, 4)");
}

// Random small polygon soups (4-8 vertices, 1-10 faces, some quads) reach every way a face can be
// refused, including OpenMesh's failed patch re-linking; each either loads as the file's fans, in
// order (some reversed to agree with their neighbours), or fails with a MeshError that names the
// file and a face. (Run under ASan/UBSan with
// 20,000 soups and 12,000 byte-mutated OFF/OBJ/PLY files when written: no report.)
TEST(MeshIo, RandomSoupsLoadAsTheirFansOrNameTheRefusedFace) {
  TempDir dir;
  std::mt19937 rng(7);
  int loaded = 0, reoriented = 0;
  std::map<std::string, int> refusals;
  for (int trial = 0; trial < 3000; ++trial) {
    const int nv = 4 + static_cast<int>(rng() % 5), nf = 1 + static_cast<int>(rng() % 10);
    std::string off = "OFF\n" + std::to_string(nv) + " " + std::to_string(nf) + " 0\n";
    for (int v = 0; v < nv; ++v)
      off += std::to_string(rng() % 100) + " " + std::to_string(rng() % 100) + " " +
             std::to_string(rng() % 100) + "\n";
    std::vector<std::array<int, 3>> fans;
    for (int f = 0; f < nf; ++f) {
      // Distinct corners but for one face in ten, so that most faces reach the half-edge mesh.
      std::vector<int> corner(nv);
      std::iota(corner.begin(), corner.end(), 0);
      std::shuffle(corner.begin(), corner.end(), rng);
      corner.resize(rng() % 5 == 0 ? 4 : 3);
      if (rng() % 10 == 0) corner[2] = corner[0];
      off += std::to_string(corner.size());
      for (int c : corner) (off += ' ') += std::to_string(c);
      off += "\n";
      for (std::size_t j = 1; j + 1 < corner.size(); ++j)
        fans.push_back({corner[0], corner[j], corner[j + 1]});
    }
    const std::string path = dir.write("soup.off", off);
    try {
      ReadReport report;
      const TriangleMesh m = read_mesh(path, &report);
      ASSERT_EQ(m.num_faces(), static_cast<Eigen::Index>(fans.size())) << off;
      long long reversed = 0;
      for (std::size_t t = 0; t < fans.size(); ++t) {
        // Each fan as the file lists it, or reversed to agree with its neighbours.
        const bool as_listed =
            m.faces.row(t) == Eigen::RowVector3i(fans[t][0], fans[t][1], fans[t][2]);
        reversed += !as_listed;
        if (!as_listed) {
          ASSERT_EQ(m.faces.row(t), Eigen::RowVector3i(fans[t][0], fans[t][2], fans[t][1])) << off;
        }
      }
      ASSERT_EQ(report.reoriented_faces, reversed) << off;
      ASSERT_EQ(validate_mesh(m, path, {true, ""}).misoriented_edges, 0) << off;
      ++loaded;
      reoriented += reversed > 0;
    } catch (const MeshError& e) {
      const std::string msg = e.what();
      ASSERT_EQ(msg.rfind(path + ": ", 0), 0u) << msg;
      if (msg.find(" repeats vertex ") != std::string::npos) {
        ++refusals["repeats"];
      } else if (msg.find("non-orientable mesh: ") != std::string::npos) {
        ++refusals["non-orientable"];
      } else {
        const auto at = msg.find("cannot be added: its ");
        ASSERT_NE(at, std::string::npos) << msg;
        ASSERT_NE(msg.find("non-manifold mesh: "), std::string::npos) << msg;
        ++refusals[msg.substr(at + 21, 6)];  // "edge (", "vertex", "faces "
      }
    }
  }
  // The bounds only make sure the soups keep reaching every branch.
  EXPECT_GT(loaded, 100);
  EXPECT_GT(reoriented, 20);
  EXPECT_GT(refusals["repeats"], 100);
  EXPECT_GT(refusals["edge ("], 100);
  EXPECT_GT(refusals["faces "], 5);  // the faces around a vertex cannot be ordered into one fan
  EXPECT_GT(refusals["vertex"], 0);  // a vertex already surrounded by a closed fan
}

// Three triangles on the edge (0, 1): a fin, which no half-edge mesh holds (face 2 is refused).
TriangleMesh fin_mesh() {
  TriangleMesh fin;
  fin.vertices.resize(5, 3);
  fin.vertices << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1;
  fin.faces.resize(3, 3);
  fin.faces << 0, 1, 2, 1, 0, 3, 0, 1, 4;
  return fin;
}

TEST(MeshIo, WritingANonManifoldMeshFails) {
  TempDir dir;
  const TriangleMesh fin = fin_mesh();
  for (const char* name : {"fin.off", "fin.ply", "fin.stl"}) {
    const std::string path = dir.file(name);
    try {
      write_mesh(path, fin);
      FAIL() << "wrote " << path;
    } catch (const MeshError& e) {
      EXPECT_NE(
          std::string(e.what()).find("cannot write: non-manifold mesh: face 2 (vertices 0, 1, 4)"),
          std::string::npos)
          << e.what();
    }
    EXPECT_FALSE(std::filesystem::exists(path)) << path;
  }
  // The STL writer needs the half-edge mesh, so it checks whatever the caller vouches for.
  EXPECT_THROW(write_mesh(dir.file("fin_trusted.stl"), fin, true, FaceCheck::trusted), MeshError);
  EXPECT_FALSE(std::filesystem::exists(dir.file("fin_trusted.stl")));
  // The check on its own names the mesh and the face, as on writing.
  try {
    check_half_edge_faces(fin, "the fin");
    FAIL() << "no MeshError";
  } catch (const MeshError& e) {
    EXPECT_NE(std::string(e.what()).find("the fin: non-manifold mesh: face 2 (vertices 0, 1, 4)"),
              std::string::npos)
        << e.what();
  }
}

std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// FaceCheck::trusted skips only the check: the files are byte for byte those written after it.
// And it does skip it (the speed-up of writing a flow's frames), which the fin shows: written
// as trusted, it is in the file, and reading that file back names it.
TEST(MeshIo, TrustedFacesWriteTheSameBytes) {
  TempDir dir;
  TriangleMesh m = make_icosphere(2);
  m.vertices *= 1.0 / 3.0;  // doubles that need all 17 digits
  for (const char* ext : {".ply", ".off", ".obj", ".stl"})
    for (const bool binary : {true, false}) {
      const std::string checked = dir.file(std::string("checked") + (binary ? "_b" : "_a") + ext);
      const std::string trusted = dir.file(std::string("trusted") + (binary ? "_b" : "_a") + ext);
      write_mesh(checked, m, binary);
      write_mesh(trusted, m, binary, FaceCheck::trusted);
      const std::string bytes = file_bytes(checked);
      EXPECT_GT(bytes.size(), 1000u) << checked;
      EXPECT_EQ(bytes, file_bytes(trusted)) << trusted;
    }

  const std::string path = dir.file("fin.ply");
  write_mesh(path, fin_mesh(), true, FaceCheck::trusted);
  expect_error_naming(path, "non-manifold mesh: face 2 (vertices 0, 1, 4)");
}

TEST(MeshIo, RepeatedIndexInFace) {
  TempDir dir;
  expect_error_naming(dir.write("repeat.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 1\n"),
                      "face 0 repeats vertex 1");
  expect_error_naming(dir.write("repeat.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2\n"),
                      "the face on line 4 repeats vertex 2");
}

TEST(MeshIo, UnknownExtension) {
  TempDir dir;
  const auto path = dir.write("mesh.xyz", kTetraOff);
  try {
    read_mesh(path);
    FAIL();
  } catch (const MeshError& e) {
    EXPECT_NE(std::string(e.what()).find("mesh.xyz"), std::string::npos);
  }
}

TEST(MeshIo, QuadsAreFanTriangulated) {
  TempDir dir;
  const auto path = dir.write("quad.off", "OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n");
  const TriangleMesh m = read_mesh(path);
  EXPECT_EQ(m.num_faces(), 2);
  EXPECT_NEAR(surface_area(m), 1.0, 1e-12);
  const auto obj = dir.write(
      "quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 1\nf 1 2 3 4\nf 2 1 5\n");
  const TriangleMesh o = read_mesh(obj);
  EXPECT_EQ(o.num_faces(), 3);
  EXPECT_EQ(o.num_vertices(), 5);
  // A closed pyramid with a quad base: the PLY walk fans k - 2 triangles from each face.
  const auto ply = dir.write(
      "pyramid.ply",
      "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\n"
      "property float z\nelement face 5\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 0.5 1\n4 0 3 2 1\n3 0 1 4\n3 1 2 4\n3 2 3 4\n3 3 0 4\n");
  EXPECT_EQ(read_mesh(ply).num_faces(), 6);
}

TEST(MeshIo, AsciiKeepsDoublesExactly) {
  TempDir dir;
  TriangleMesh m = make_icosphere(1);
  m.vertices *= 1.0 / 3.0;  // not representable in float
  for (const char* name : {"x.off", "x.obj", "x.ply"}) {
    for (bool binary : {false, true}) {
      write_mesh(dir.file(name), m, binary);
      EXPECT_EQ(read_mesh(dir.file(name)).vertices, m.vertices)
          << name << (binary ? " binary" : " ascii");
    }
  }
}

// --- PLY: every record is walked (ply_format.cpp), so errors name the line (ASCII) or byte. ---

const std::string kTetraPlyHeader =
    "ply\nformat ascii 1.0\nelement vertex 4\nproperty double x\nproperty double y\nproperty "
    "double z\n"
    "element face 4\nproperty list uchar int vertex_indices\nend_header\n";  // lines 1-9
const std::string kTetraVertices = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n";           // lines 10-13
const std::string kTetraFaces = "3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n";      // lines 14-17

TEST(MeshIoPly, AsciiErrorsNameTheLine) {
  TempDir dir;
  EXPECT_EQ(
      read_mesh(dir.write("ok.ply", kTetraPlyHeader + kTetraVertices + kTetraFaces)).num_faces(),
      4);
  struct Case {
    const char* file;
    std::string vertices, faces;  // the body, lines 10-13 and 14-17
    const char* error;
  };
  const Case cases[] = {
      {"nan.ply", "0 0 0\n1 0 0\n0 nan 0\n0 0 1\n", kTetraFaces,
       "line 12: vertex 2 has a non-finite coordinate y"},
      {"range.ply", kTetraVertices, "3 0 2 1\n3 0 1 3\n3 1 2 9\n3 0 3 2\n",
       "line 16: face 2 references vertex 9 but the mesh has 4 vertices"},
      {"short.ply", kTetraVertices, "3 0 2 1\n3 0 1 3\n",
       "the file ends at line 16 before face 2 of 4 is complete"},
      // A value missing or one too many: the error is on that line, not a misread of the rest.
      {"missing.ply", "0 0 0\n1 0\n0 1 0\n0 0 1\n", kTetraFaces,
       "line 11: vertex 1 of 4 ends after 2 values"},
      {"extra.ply", "0 0 0\n1 0 0 7\n0 1 0\n0 0 1\n", kTetraFaces,
       "line 11: vertex 1 of 4 has more values than its 3"},
      {"two.ply", kTetraVertices, "3 0 2 1\n3 0 1\n3 1 2 3\n3 0 3 2\n",
       "line 15: face 1 of 4 ends after 3 values"},
      {"word.ply", kTetraVertices, "3 0 2 1\n3 0 1 x\n3 1 2 3\n3 0 3 2\n",
       "line 15: face 1 corner 2: 'x' is not an integer"},
      {"corners.ply", kTetraVertices, "3 0 2 1\n2 0 1\n3 1 2 3\n3 0 3 2\n",
       "line 15: face 1 has 2 corners"},
      {"letters.ply", "0 0 0\n1 0 zz\n0 1 0\n0 0 1\n", kTetraFaces,
       "line 11: vertex 1 of 4: 'zz' cannot be parsed as a number"},
  };
  for (const Case& c : cases)
    expect_error_naming(dir.write(c.file, kTetraPlyHeader + c.vertices + c.faces), c.error);
  // A CRLF file reads as its LF twin.
  std::string crlf;
  for (char c : kTetraPlyHeader + kTetraVertices + kTetraFaces)
    crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  EXPECT_EQ(read_mesh(dir.write("crlf.ply", crlf)).vertices,
            read_mesh(dir.file("ok.ply")).vertices);
  // Blank lines between records and trailing blanks are fine.
  EXPECT_EQ(read_mesh(dir.write("blank.ply", kTetraPlyHeader + "0 0 0\n\n1 0 0  \n0 1 0\n0 0 1\n" +
                                                 kTetraFaces + "\n"))
                .num_faces(),
            4);
}

TEST(MeshIoPly, HeaderErrorsNameTheLine) {
  TempDir dir;
  auto with = [&](const std::string& from, const std::string& to) {
    std::string h = kTetraPlyHeader;
    h.replace(h.find(from), from.size(), to);
    return h + kTetraVertices + kTetraFaces;
  };
  expect_error_naming(dir.write("format.ply", with("format ascii", "format utf8")),
                      "line 2: unknown format 'utf8'");
  expect_error_naming(dir.write("type.ply", with("property double y", "property real y")),
                      "line 5: unknown property type 'real'");
  expect_error_naming(dir.write("noz.ply", with("property double z", "property double w")),
                      "no scalar property 'z'");
  expect_error_naming(dir.write("nolist.ply", with("vertex_indices", "corners")),
                      "no list property 'vertex_indices'");
  expect_error_naming(
      dir.write("huge.ply", with("element vertex 4", "element vertex 4000000000000")),
      "declares 4000000000000 vertices, more than the file's body can hold");
  expect_error_naming(
      dir.write("noend.ply", kTetraPlyHeader.substr(0, kTetraPlyHeader.find("end_header"))),
      "no end_header");
}

// Little- or big-endian bytes of a value, to write binary test files by hand.
template <typename T>
std::string bytes(T value, bool big_endian) {
  std::string b(sizeof(T), '\0');
  std::memcpy(b.data(), &value, sizeof(T));
  if (big_endian == (std::endian::native == std::endian::little)) std::reverse(b.begin(), b.end());
  return b;
}

// A binary tetrahedron with float coordinates, an extra per-vertex property and an extra element
// after the faces: what scanners and laser-scan exports write.
std::string binary_tetra(bool big_endian, int bad_index = 2, int faces_written = 4) {
  std::string s =
      std::string("ply\nformat ") + (big_endian ? "binary_big_endian" : "binary_little_endian") +
      " 1.0\ncomment test\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "property uchar red\nelement face 4\nproperty list uchar int vertex_indices\n"
      "element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n";
  const float v[4][3] = {{0, 0, 0}, {0.1f, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (const auto& p : v) {
    for (float c : p) s += bytes(c, big_endian);
    s += bytes(std::uint8_t{200}, big_endian);
  }
  const int f[4][3] = {{0, 2, 1}, {0, 1, 3}, {1, bad_index, 3}, {0, 3, 2}};
  for (int i = 0; i < faces_written; ++i) {
    s += bytes(std::uint8_t{3}, big_endian);
    for (int c : f[i]) s += bytes(std::int32_t{c}, big_endian);
  }
  if (faces_written == 4)
    s += bytes(std::int32_t{0}, big_endian) + bytes(std::int32_t{1}, big_endian);
  return s;
}

TEST(MeshIoPly, BinaryBothByteOrders) {
  TempDir dir;
  for (bool big : {false, true}) {
    const TriangleMesh m = read_mesh(dir.write(big ? "big.ply" : "little.ply", binary_tetra(big)));
    ASSERT_EQ(m.num_vertices(), 4);
    ASSERT_EQ(m.num_faces(), 4);
    EXPECT_EQ(m.vertices(1, 0), double(0.1f)) << "float widened exactly, big endian " << big;
    EXPECT_TRUE(test::same_face(m.faces.row(2), Eigen::RowVector3i(1, 2, 3)));
    EXPECT_GT(test::signed_volume(m), 0);
  }
  // Vertex records take 13 bytes, face records 13 (count, then three indices).
  auto header_bytes = [](bool big) { return binary_tetra(big).find("end_header\n") + 11; };
  expect_error_naming(dir.write("range_bin.ply", binary_tetra(false, 6)),
                      "byte " + std::to_string(header_bytes(false) + 4 * 13 + 2 * 13 + 5) +
                          ": face 2 references vertex 6");
  expect_error_naming(dir.write("short_bin.ply", binary_tetra(true, 2, 3)),
                      "the file ends at byte " +
                          std::to_string(header_bytes(true) + 4 * 13 + 3 * 13) +
                          " before face 3 of 4");
}

// Found by fuzzing: a float-typed list count or index beyond long long's range (or infinite) was
// converted to an integer, which is undefined; it is now an error naming the value's place.
TEST(MeshIoPly, FloatCountsAndIndicesOutOfRangeAreErrors) {
  TempDir dir;
  const std::string header =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list float float vertex_indices\nend_header\n";
  std::string vertices;
  for (int i = 0; i < 9; ++i) vertices += bytes(float(i % 4 == 0), false);
  for (float huge : {1e30f, std::numeric_limits<float>::infinity()}) {
    const std::string as_count = header + vertices + bytes(huge, false);
    expect_error_naming(dir.write("count.ply", as_count), "out of range");
    const std::string as_index = header + vertices + bytes(3.0f, false) + bytes(0.0f, false) +
                                 bytes(huge, false) + bytes(2.0f, false);
    expect_error_naming(dir.write("index.ply", as_index), "out of range");
  }
}

// Found by fuzzing: an element with records but no properties made the reader loop over its
// count (1e16 records of nothing) instead of refusing it.
TEST(MeshIoPly, AnElementWithRecordsButNoPropertiesIsAnError) {
  TempDir dir;
  const std::string ply =
      "ply\nformat binary_little_endian 1.0\nelement junk 9999999999999999\nelement vertex 3\n"
      "property float x\nproperty float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  expect_error_naming(dir.write("empty_element.ply", ply),
                      "element 'junk' has 9999999999999999 records but no properties");
}

// A binary tetrahedron whose coordinates are of type T (spelled `name` in the header) and whose
// faces are a list of index type I with count type C: every scalar type, either spelling, read
// in either byte order. Signed types get the negative corner -1 (a sign-extension check).
template <typename T, typename C, typename I>
void expect_binary_types(const TempDir& dir, const std::string& name, const std::string& count,
                         const std::string& index, bool big) {
  const std::string header =
      std::string("ply\nformat ") + (big ? "binary_big_endian" : "binary_little_endian") +
      " 1.0\nelement vertex 4\nproperty " + name + " x\nproperty " + name + " y\nproperty " + name +
      " z\nelement face 4\nproperty list " + count + " " + index + " vertex_indices\nend_header\n";
  const int low = std::is_signed_v<T> ? -1 : 0;
  const int v[4][3] = {{low, low, low}, {2, low, low}, {low, 2, low}, {low, low, 2}};
  std::string body;
  for (const auto& p : v)
    for (int c : p) body += bytes(static_cast<T>(c), big);
  const int f[4][3] = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
  for (const auto& face : f) {
    body += bytes(static_cast<C>(3), big);
    for (int c : face) body += bytes(static_cast<I>(c), big);
  }
  const std::string label = name + "/" + count + "/" + index + (big ? " big" : " little");
  const TriangleMesh m = read_mesh(dir.write("types.ply", header + body));
  ASSERT_EQ(m.num_vertices(), 4) << label;
  ASSERT_EQ(m.num_faces(), 4) << label;
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(m.vertices.row(i), Eigen::RowVector3d(v[i][0], v[i][1], v[i][2]))
        << label << " vertex " << i;
    EXPECT_EQ(m.faces.row(i), Eigen::RowVector3i(f[i][0], f[i][1], f[i][2]))
        << label << " face " << i;
  }
}

TEST(MeshIoPly, EveryScalarTypeInBothSpellingsAndByteOrders) {
  TempDir dir;
  for (bool big : {false, true}) {
    expect_binary_types<std::int8_t, std::uint8_t, std::int32_t>(dir, "char", "uchar", "int", big);
    expect_binary_types<std::int8_t, std::uint16_t, std::uint32_t>(dir, "int8", "ushort", "uint32",
                                                                   big);
    expect_binary_types<std::uint8_t, std::int8_t, std::int16_t>(dir, "uchar", "char", "short",
                                                                 big);
    expect_binary_types<std::uint8_t, std::uint32_t, std::uint16_t>(dir, "uint8", "uint", "uint16",
                                                                    big);
    expect_binary_types<std::int16_t, std::int16_t, std::uint8_t>(dir, "short", "int16", "uint8",
                                                                  big);
    expect_binary_types<std::int16_t, std::int32_t, std::int8_t>(dir, "int16", "int32", "int8",
                                                                 big);
    expect_binary_types<std::uint16_t, std::uint8_t, std::int32_t>(dir, "ushort", "uint8", "int",
                                                                   big);
    expect_binary_types<std::uint16_t, std::uint8_t, std::int32_t>(dir, "uint16", "uchar", "int32",
                                                                   big);
    expect_binary_types<std::int32_t, std::uint8_t, std::uint32_t>(dir, "int", "uchar", "uint",
                                                                   big);
    expect_binary_types<std::int32_t, std::uint8_t, std::int32_t>(dir, "int32", "uchar", "int",
                                                                  big);
    expect_binary_types<std::uint32_t, std::uint8_t, std::int32_t>(dir, "uint", "uchar", "int",
                                                                   big);
    expect_binary_types<std::uint32_t, std::uint8_t, std::int32_t>(dir, "uint32", "uchar", "int",
                                                                   big);
    expect_binary_types<float, std::uint8_t, std::int32_t>(dir, "float", "uchar", "int", big);
    expect_binary_types<float, std::uint8_t, std::int32_t>(dir, "float32", "uchar", "int", big);
    expect_binary_types<double, std::uint8_t, std::int32_t>(dir, "double", "uchar", "int", big);
    expect_binary_types<double, std::uint8_t, std::int32_t>(dir, "float64", "uchar", "int", big);
  }
}

// Round trip of a torus (irrational coordinates) through every format.
// STL stores triangle soups: the reader merges equal corners in order of first appearance, so
// only the face order and each face's corner positions can be compared.
void expect_round_trip(const std::string& name, bool binary, double tol,
                       bool keeps_vertex_order = true) {
  TempDir dir;
  const TriangleMesh m = make_torus(1.0, 0.3, 24, 12);
  const auto path = dir.file(name);
  write_mesh(path, m, binary);
  // Atomic write: only the target is left in the folder.
  int files = 0;
  for ([[maybe_unused]] const auto& e :
       std::filesystem::directory_iterator(std::filesystem::path(path).parent_path()))
    ++files;
  EXPECT_EQ(files, 1);
  const TriangleMesh r = read_mesh(path);
  ASSERT_EQ(r.num_vertices(), m.num_vertices()) << name;
  ASSERT_EQ(r.num_faces(), m.num_faces()) << name;
  if (keeps_vertex_order) {
    EXPECT_LE((r.vertices - m.vertices).cwiseAbs().maxCoeff(), tol) << name;
    for (Eigen::Index f = 0; f < m.num_faces(); ++f)
      ASSERT_TRUE(test::same_face(r.faces.row(f), m.faces.row(f))) << name << " face " << f;
  } else {
    for (Eigen::Index f = 0; f < m.num_faces(); ++f) {
      bool match = false;
      for (int rot = 0; rot < 3 && !match; ++rot) {
        double err = 0;
        for (int c = 0; c < 3; ++c)
          err = std::max(err,
                         (r.vertices.row(r.faces(f, c)) - m.vertices.row(m.faces(f, (c + rot) % 3)))
                             .cwiseAbs()
                             .maxCoeff());
        match = err <= tol;
      }
      ASSERT_TRUE(match) << name << " face " << f;
    }
  }
}

TEST(MeshIo, RoundTripOff) {
  expect_round_trip("t.off", false, 1e-15);
}
TEST(MeshIo, RoundTripPlyAscii) {
  expect_round_trip("t.ply", false, 0.0);
}  // property double
TEST(MeshIo, RoundTripPlyBinary) {
  expect_round_trip("t.ply", true, 0.0);
}
TEST(MeshIo, RoundTripObj) {
  expect_round_trip("t.obj", false, 1e-15);
}
TEST(MeshIo, RoundTripStlAscii) {
  expect_round_trip("t.stl", false, 1e-6, false);
}
TEST(MeshIo, RoundTripStlBinary) {
  expect_round_trip("t.stl", true, 1e-6, false);
}

// The first read-chunk boundary of an ASCII STL (mesh_io.cpp reads an 84-byte head, then 1 MiB
// chunks), and `m` written as ASCII STL, as text (the tests assert that it reaches past it).
constexpr std::size_t kBoundary = 84 + (std::size_t(1) << 20);
std::string ascii_stl_past_the_first_chunk(TempDir& dir, const TriangleMesh& m) {
  const std::string plain = dir.file("plain.stl");
  write_mesh(plain, m, false);
  return file_bytes(plain);
}

// An ASCII STL is counted in chunks of 1 MiB read after its 84-byte head (mesh_io.cpp: the
// facets its lines open, not the word "facet", which a solid's name may hold). The count notices a
// facet OpenMesh drops without an error (here a degenerate one), so a keyword missed or counted
// twice at a chunk boundary would hide it or blame a wrong number.
// One file per way a keyword can meet the first boundary, moved there by blanks ("fa|cet",
// "end|facet", "endfa|cet", and an opening "facet" that ends exactly at it, seen again behind
// the next chunk), so that no two mistakes can cancel.
TEST(MeshIo, AsciiStlCountedAcrossReadChunks) {
  TempDir dir;
  const TriangleMesh m = make_icosphere(5);
  std::string text = ascii_stl_past_the_first_chunk(dir, m);
  ASSERT_GT(text.size(), kBoundary + 1000);
  text.insert(text.rfind("endsolid"),
              "facet normal 0 0 1\nouter loop\nvertex 7 7 7\nvertex 7 7 7\nvertex 8 7 "
              "7\nendloop\nendfacet\n");
  const std::string expected = "only " + std::to_string(m.num_faces()) + " of the file's " +
                               std::to_string(m.num_faces() + 1) + " triangles could be added";
  // Blanks before the last `word` that fits, so that its "facet" starts at byte `facet_at`.
  const auto place = [&](const std::string& word, std::size_t facet_at) {
    std::string placed = text;
    const std::size_t offset = word.find("facet"), p = placed.rfind(word, facet_at - offset);
    ASSERT_NE(p, std::string::npos);
    placed.insert(p, facet_at - offset - p, ' ');
    ASSERT_EQ(placed.compare(facet_at, 5, "facet"), 0);
    SCOPED_TRACE(word + " at " + std::to_string(facet_at));
    expect_error_naming(dir.write("chunks.stl", placed), expected);
  };
  place("facet normal", kBoundary - 2);
  place("endfacet", kBoundary);
  place("endfacet", kBoundary - 2);
  place("facet normal", kBoundary - 5);
}

// The tetrahedron of kTetraOff as ASCII STL, one keyword per line: line 3 opens the first facet,
// lines 4-6 are its corners (then 11-13, 18-20, 25-27).
const char* kTetraStl =
    "solid t\nfacet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 0 1 0\nvertex 1 0 "
    "0\nendloop\nendfacet\n"
    "facet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 0 1\nendloop\nendfacet\n"
    "facet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 0 0 1\nvertex 0 1 0\nendloop\nendfacet\n"
    "facet normal 0 0 0\nouter loop\nvertex 1 0 0\nvertex 0 1 0\nvertex 0 0 "
    "1\nendloop\nendfacet\nendsolid t\n";

// text with its line `number` (from 1) replaced by `line` (which may hold several lines, or none).
std::string with_line(const std::string& text, int number, const std::string& line) {
  std::size_t begin = 0;
  for (int n = 1; n < number; ++n) begin = text.find('\n', begin) + 1;
  return text.substr(0, begin) + line + text.substr(text.find('\n', begin));
}

// OpenMesh's reader takes the three lines after one containing "outer" as a facet's corners, a
// word and three floats each, and reads bad text without a word (`vertex 0 1 zz` as (0, 1, 0), a
// missing coordinate as the last vertex's, 1e999 as FLT_MAX): the streaming pass that counts the
// facets checks those lines, and the error names the line.
TEST(MeshIo, AsciiStlVertexLinesChecked) {
  TempDir dir;
  const std::string tetra = kTetraStl;
  ASSERT_EQ(read_mesh(dir.write("tetra.stl", tetra)).num_faces(), 4);
  const std::pair<std::string, std::string> bad[] = {
      {with_line(tetra, 6, "vertex 1 0 zz"),
       "line 6: vertex coordinate 'zz' is not a number: 'vertex 1 0 zz'"},
      {with_line(tetra, 5, "  vertex 0 1"),
       "line 5: vertex line with 2 of 3 coordinates: 'vertex 0 1'"},
      {with_line(tetra, 12, "vertex 1e999 0 0"), "line 12: non-finite vertex coordinate '1e999'"},
      {with_line(tetra, 12, "vertex 1e39 0 0"),
       "line 12: non-finite vertex coordinate '1e39' (STL coordinates are 32-bit floats"},
      {with_line(tetra, 12, "vertex -inf 0 0"), "line 12: non-finite vertex coordinate '-inf'"},
      {with_line(tetra, 27, "vertex 0 0 nan"), "line 27: non-finite vertex coordinate 'nan'"},
      {with_line(tetra, 12, "vertex 0x1p0 0 0"),
       "line 12: vertex coordinate '0x1p0' is not a number"},
      {with_line(tetra, 12, "vertex 1 0 0 0"), "line 12: vertex line with more than 3 coordinates"},
      {with_line(tetra, 6, "endloop"),
       "line 6: expected 'vertex x y z', corner 3 of the facet opened by 'outer' on line 3, found "
       "'endloop'"},
      {with_line(tetra, 3, "outer loop\n"),
       "line 4: expected 'vertex x y z', corner 1 of the facet opened by 'outer' on line 3, found "
       "an empty line"},
      {with_line(tetra, 6, "vertex 1 0 0\nvertex 1 1 0"),
       "line 7: a vertex line outside a facet's three corners"},
      {with_line(tetra, 1, "solid outer_shell"),
       "line 2: expected 'vertex x y z', corner 1 of the facet opened by 'outer' on line 1"},
      {tetra.substr(0, tetra.find("vertex 1 0 0")),
       "the file ends 1 vertex line(s) short of the facet opened on line 3"},
  };
  for (const auto& [text, message] : bad) {
    SCOPED_TRACE(message);
    expect_error_naming(dir.write("bad.stl", text), message);
  }
  // What `>>` reads as the same numbers still loads: signs, exponents, tabs, an underflow to 0,
  // CR LF line ends, no newline at the end.
  std::string good =
      with_line(with_line(tetra, 4, "vertex 0 0 1e-50"), 6, "\tvertex\t+1.0E+0\t0.0\t-0e-3 ");
  good.pop_back();
  std::string crlf;
  for (char c : good) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  for (const std::string& text : {good, crlf}) {
    const TriangleMesh m = read_mesh(dir.write("good.stl", text));
    EXPECT_EQ(m.num_faces(), 4);
    EXPECT_EQ(m.num_vertices(), 4);
  }
  // The facets are those 'outer' opens, not the word "facet": a solid may carry it in its name.
  for (const char* name : {"solid facet_x", "solid endfacet facet", "solid"}) {
    SCOPED_TRACE(name);
    EXPECT_EQ(read_mesh(dir.write("named.stl", with_line(tetra, 1, name))).num_faces(), 4);
  }
}

// STL's keywords are lowercase, but files in capitals exist ("SOLID", "OUTER LOOP", "VERTEX"):
// OpenMesh's reader opens a facet at "OUTER" as at "outer", so such a file is an ASCII STL here
// too and loads as its lowercase twin does, coordinates exactly (as 32-bit floats, as STL holds
// them). In mixed case ("Outer Loop"), which OpenMesh's reader opens no facet at, it is refused
// naming the line.
TEST(MeshIo, AsciiStlInCapitals) {
  TempDir dir;
  // kTetraStl's tetrahedron, with corners whose text is not their digits alone.
  const std::string a = "0.5 0.25 -1", b = "2.75 0.25 -1", c = "0.5 3.125e0 -1",
                    d = "0.1 0.25 1.5e1";
  const auto facet = [](const std::string& p, const std::string& q, const std::string& r) {
    return "facet normal 0 0 0\nouter loop\nvertex " + p + "\nvertex " + q + "\nvertex " + r +
           "\nendloop\nendfacet\n";
  };
  const std::string lower = "solid t\n" + facet(a, c, b) + facet(a, b, d) + facet(a, d, c) +
                            facet(b, c, d) + "endsolid t\n";
  std::string upper = lower;
  std::transform(upper.begin(), upper.end(), upper.begin(),
                 [](unsigned char ch) { return std::toupper(ch); });
  ASSERT_NE(upper.find("VERTEX 0.5 3.125E0 -1\n"), std::string::npos);
  const TriangleMesh twin = read_mesh(dir.write("lower.stl", lower));
  const TriangleMesh m = read_mesh(dir.write("upper.stl", upper));
  ASSERT_EQ(m.num_vertices(), 4);
  ASSERT_EQ(m.num_faces(), 4);
  // Vertices in the order of their first corner: a, c, b, d.
  Eigen::Matrix<double, 4, 3> points;
  points << 0.5, 0.25, -1, 0.5, 3.125, -1, 2.75, 0.25, -1, static_cast<double>(0.1f), 0.25, 15;
  EXPECT_TRUE(m.vertices == points) << m.vertices;
  EXPECT_TRUE(m.vertices == twin.vertices);
  EXPECT_TRUE(m.faces == twin.faces);
  const MeshReport report = validate_mesh(m, "upper.stl");
  EXPECT_TRUE(report.closed());

  std::string mixed = lower;
  for (const auto& [from, to] : {std::pair<std::string, std::string>{"solid", "Solid"},
                                 {"facet normal", "Facet Normal"},
                                 {"outer loop", "Outer Loop"},
                                 {"vertex", "Vertex"}}) {
    for (auto p = mixed.find(from); p != std::string::npos; p = mixed.find(from, p + 1))
      mixed.replace(p, from.size(), to);
  }
  expect_error_naming(
      dir.write("mixed.stl", mixed),
      "line 3: 'Outer Loop': OpenMesh's reader opens a facet only at 'outer' or 'OUTER'");
}

// The lines are checked in the same 1 MiB chunks the facets are counted in, so a line, a keyword
// or a number can straddle a chunk: each is put across the first boundary after the 84-byte head
// (by widening the indentation of a vertex line), once valid (the file loads) and once bad (the
// error names the right line).
TEST(MeshIo, AsciiStlLinesCheckedAcrossReadChunks) {
  TempDir dir;
  const TriangleMesh m = make_icosphere(5);
  const std::string text = ascii_stl_past_the_first_chunk(dir, m);
  ASSERT_GT(text.size(), kBoundary + 1000);
  // A vertex line ending some 200 bytes before the boundary (its number: `number`) is replaced by
  // `line`, indented so that its byte `split` falls on the boundary.
  const std::size_t at = text.rfind("\nvertex", kBoundary - 200) + 1, end = text.find('\n', at);
  const std::string original = text.substr(at, end - at);
  const long long number =
      std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n') + 1;
  const auto place = [&](const std::string& line, std::size_t split, const std::string& message) {
    ASSERT_LE(at + split, kBoundary);
    const std::string placed =
        text.substr(0, at) + std::string(kBoundary - split - at, ' ') + line + text.substr(end);
    ASSERT_EQ(placed.compare(kBoundary - split, line.size() + 1, line + "\n"), 0);
    SCOPED_TRACE("'" + line + "' split at " + std::to_string(split) + ", line " +
                 std::to_string(number));
    const auto path = dir.write("chunks.stl", placed);
    if (message.empty()) {
      EXPECT_EQ(read_mesh(path).num_faces(), m.num_faces());
    } else {
      expect_error_naming(path, "line " + std::to_string(number) + ": " + message);
    }
  };
  place(original, 0, "");                    // the line starts the chunk
  place(original, 3, "");                    // "ver|tex"
  place(original, 10, "");                   // inside its first number
  place(original, original.size(), "");      // its newline starts the chunk
  place(original, original.size() + 1, "");  // its newline ends the chunk
  place("vertex 0 0 1e999", 13, "non-finite vertex coordinate '1e999'");  // "1e|999"
  place("vertex 0 1 zz", 12, "vertex coordinate 'zz' is not a number");   // "z|z"
  place("vertex 0 1", 10, "vertex line with 2 of 3 coordinates");  // its newline starts the chunk
  place("vertex 0 1 0 0", 3, "vertex line with more than 3 coordinates");  // "ver|tex"
}

// A binary STL is checked by its header's triangle count against the file's length; one whose
// header starts with "solid" (as some exporters write) is still binary: it is not all text.
TEST(MeshIo, BinaryStlHeaderAndLength) {
  TempDir dir;
  const TriangleMesh m = make_icosphere(1);
  const std::string good = dir.file("good.stl");
  write_mesh(good, m, true);
  std::string bytes = file_bytes(good);
  ASSERT_EQ(bytes.size(), 84u + 50u * static_cast<size_t>(m.num_faces()));
  EXPECT_EQ(read_mesh(good).num_faces(), m.num_faces());

  expect_error_naming(dir.write("truncated.stl", bytes.substr(0, bytes.size() - 10)),
                      "binary STL announces " + std::to_string(m.num_faces()) + " triangles");
  expect_error_naming(dir.write("short.stl", bytes.substr(0, 60)),
                      "shorter than its 84-byte header");

  std::string solid = bytes;
  solid.replace(0, 12, "solid binary");
  const TriangleMesh r = read_mesh(dir.write("solid_header.stl", solid));
  EXPECT_EQ(r.num_faces(), m.num_faces());
  EXPECT_EQ(r.num_vertices(), m.num_vertices());
}

// OpenMesh takes an STL whose length is not 84 + 50 N (N the header's count) for ASCII and reads
// nothing, or garbage, from a binary one; mesh_io.cpp decides the layout instead. Bytes after the
// N triangles that cannot hold a triangle (fewer than 50) or are all zero are padding: the file
// loads as without them, "solid" header or not. Other bytes after them (triangles the count may
// leave out) and a file too short for them are refused, naming the count and both lengths.
TEST(MeshIo, BinaryStlTrailingBytes) {
  TempDir dir;
  const TriangleMesh m = make_icosphere(1);
  const std::string good = dir.file("good.stl");
  write_mesh(good, m, true);
  const std::string bytes = file_bytes(good);
  const TriangleMesh expected = read_mesh(good);
  ASSERT_EQ(expected.num_faces(), m.num_faces());
  std::string solid = bytes;
  solid.replace(0, 16, "solid facet_mesh");  // header words an ASCII STL would start with
  for (const std::string& body : {bytes, solid}) {
    for (const std::string& tail :
         {std::string("\n"), std::string(49, 'x'), std::string(4096, '\0')}) {
      SCOPED_TRACE(body.substr(0, 5) + " header, " + std::to_string(tail.size()) + " bytes after");
      const TriangleMesh r = read_mesh(dir.write("padded.stl", body + tail));
      ASSERT_EQ(r.num_faces(), expected.num_faces());
      ASSERT_EQ(r.num_vertices(), expected.num_vertices());
      EXPECT_TRUE(r.vertices == expected.vertices);
      EXPECT_TRUE(r.faces == expected.faces);
    }
  }
  const std::string n = std::to_string(m.num_faces());
  const std::string announced = "binary STL announces " + n + " triangles (84 + 50 * " + n + " = " +
                                std::to_string(bytes.size()) + " bytes) but the file has ";
  const std::string record = bytes.substr(84, 50);  // a triangle's, nonzero
  expect_error_naming(dir.write("extra.stl", bytes + record),
                      announced + std::to_string(bytes.size() + 50) +
                          " bytes: the 50 bytes after its last triangle");
  expect_error_naming(dir.write("extra.stl", bytes + std::string(60, '\0') + record),
                      announced + std::to_string(bytes.size() + 110) + " bytes");
  expect_error_naming(dir.write("truncated.stl", bytes.substr(0, bytes.size() - 10)),
                      announced + std::to_string(bytes.size() - 10) + " bytes");
  expect_error_naming(
      dir.write("truncated.stl", solid.substr(0, bytes.size() - 10)),
      announced + std::to_string(bytes.size() - 10) + " bytes (it starts with 'solid'");
}

// A binary OFF: its header line, then 32-bit words, little-endian (as OpenMesh writes it on
// x86) unless big_endian (as Geomview's spec has it).
struct BinaryOff {
  std::string bytes;
  bool big_endian = false;
  explicit BinaryOff(const std::string& header = "OFF BINARY") : bytes(header + "\n") {}
  BinaryOff& word(std::uint32_t w) {
    for (int i = 0; i < 4; ++i) bytes += static_cast<char>(w >> 8 * (big_endian ? 3 - i : i));
    return *this;
  }
  BinaryOff& real(float x) { return word(std::bit_cast<std::uint32_t>(x)); }
};

// The tetrahedron of kTetraOff with vertex 3 at z = 0.1f, its faces followed by Geomview's colour
// count 0 where colour_counts, and with a normal after each point where normals.
BinaryOff binary_off_tetra(bool colour_counts = false, bool normals = false,
                           bool big_endian = false) {
  BinaryOff off(normals ? "NOFF BINARY" : "OFF BINARY");
  off.big_endian = big_endian;
  off.word(4).word(4).word(0);
  const float points[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 0.1f}};
  for (const auto& p : points) {
    off.real(p[0]).real(p[1]).real(p[2]);
    if (normals) off.real(0).real(0).real(1);
  }
  for (const auto& f : {std::array<int, 3>{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}}) {
    off.word(3).word(f[0]).word(f[1]).word(f[2]);
    if (colour_counts) off.word(0);
  }
  return off;
}

// Binary OFF is walked in the layout OpenMesh reads and writes (the bytes of binary_off_tetra() are
// those OpenMesh 9's writer writes for it): floats widened exactly, polygons fanned as in ASCII.
TEST(MeshIo, BinaryOffInOpenMeshsLayout) {
  TempDir dir;
  for (bool normals : {false, true}) {
    SCOPED_TRACE(normals ? "NOFF" : "OFF");
    const auto path =
        dir.write(normals ? "tetra_n.off" : "tetra.off", binary_off_tetra(false, normals).bytes);
    const TriangleMesh m = read_mesh(path);
    ASSERT_EQ(m.num_vertices(), 4);
    ASSERT_EQ(m.num_faces(), 4);
    EXPECT_EQ(m.vertices.row(3), Eigen::RowVector3d(0, 0, static_cast<double>(0.1f)));
    const TriangleMesh ascii = read_mesh(dir.write("tetra_ascii.off", kTetraOff));
    EXPECT_EQ(m.faces, ascii.faces);
    const MeshReport r = validate_mesh(m, path);
    EXPECT_TRUE(r.closed());
    EXPECT_EQ(r.faces, 4);
  }
  // A pyramid with a quad base: 6 triangles, as the ASCII file gives them.
  BinaryOff pyramid;
  pyramid.word(5).word(5).word(0);
  for (float x : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 1.f, 1.f, 0.f, 0.f, 1.f, 0.f, 0.5f, 0.5f, 1.f})
    pyramid.real(x);
  pyramid.word(4).word(0).word(3).word(2).word(1);
  for (std::uint32_t a = 0; a < 4; ++a) pyramid.word(3).word(a).word((a + 1) % 4).word(4);
  const TriangleMesh b = read_mesh(dir.write("pyramid.off", pyramid.bytes));
  const TriangleMesh a = read_mesh(dir.write("pyramid_ascii.off",
                                             "OFF\n5 5 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 0.5 1\n"
                                             "4 0 3 2 1\n3 0 1 4\n3 1 2 4\n3 2 3 4\n3 3 0 4\n"));
  EXPECT_EQ(b.faces, a.faces);
  EXPECT_EQ(b.vertices, a.vertices);
  EXPECT_EQ(b.num_faces(), 6);
}

// OpenMesh's reader loads a file in another layout without a word: Geomview's colour count 0
// after each face read as the next face's corner count made it skip every other face (the
// tetrahedron loaded as 2 faces with a boundary). Every such mismatch is an error naming the file.
TEST(MeshIo, BinaryOffLosesNoFace) {
  TempDir dir;
  expect_error_naming(
      dir.write("colours.off", binary_off_tetra(true).bytes),
      "face 1 (byte 87) has 0 corners (a Geomview colour count after face 0's indices?");
  expect_error_naming(dir.write("big.off", binary_off_tetra(false, false, true).bytes),
                      "read big-endian (Geomview's byte order) the counts would be 4 and 4");
  expect_error_naming(dir.write("trailing.off", binary_off_tetra().word(0).bytes),
                      "4 bytes after the last of its 4 faces (byte 135)");
  std::string bytes = binary_off_tetra().bytes;
  // Counts are checked against the length before anything is read (layout: 11 header bytes, 12
  // of counts, 12 per vertex from byte 23, 16 per triangle from byte 71).
  expect_error_naming(
      dir.write("truncated.off", bytes.substr(0, bytes.size() - 2)),
      "announces 4 vertices and 4 faces, at least 124 bytes, but has 122 after its header line");
  std::string seven = bytes;
  seven[119] = 7;
  expect_error_naming(
      dir.write("seven.off", seven),
      "face 3 (byte 119) announces 7 corners, more than the rest of the file holds");
  BinaryOff range = binary_off_tetra();
  range.bytes.resize(range.bytes.size() - 4);
  expect_error_naming(dir.write("range.off", range.word(9).bytes),
                      "face 3 (byte 119) references vertex 9 but the mesh has 4");
  BinaryOff nan = binary_off_tetra();
  nan.bytes.replace(23 + 12 + 4, 4,
                    BinaryOff("").real(std::numeric_limits<float>::quiet_NaN()).bytes.substr(1));
  expect_error_naming(dir.write("nan.off", nan.bytes),
                      "vertex 1 has a non-finite coordinate (byte 35)");
  // OpenMesh takes the first line for the header, and reads no 4D or nOFF binary file.
  expect_error_naming(dir.write("comment.off", "# made by hand\n" + bytes),
                      "header must be the first line");
  expect_error_naming(dir.write("4d.off", "4" + bytes), "other than 3 coordinates per vertex");
}

TEST(MeshIo, WriteIntoMissingFolderFails) {
  const TriangleMesh m = make_icosphere(0);
  EXPECT_THROW(write_mesh("/nonexistent_dir_xyz/out.ply", m), MeshError);
}

}  // namespace
}  // namespace mcf
