// Orienting a face list: a manifold surface listed with mixed orientation comes out consistently
// oriented (every interior edge run once each way) with the fewest faces reversed; an edge in
// three faces is named as non-manifold, a Möbius strip as non-orientable; read_mesh does it for
// files and says how many faces it reversed.

#include "datasets/generators.h"
#include "datasets/mesh_io.h"
#include "datasets/mesh_spec.h"
#include "datasets/orientation.h"
#include "datasets/validate.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <sstream>
#include <string>

namespace mcf {
namespace {

using test::TempDir;

/// A Möbius strip of `n` quads (two triangles each) around a circle, with a half twist: the last
/// quad joins the first one's edge the other way round.
TriangleMesh moebius_strip(int n) {
  TriangleMesh m;
  m.vertices.resize(2 * n, 3);
  for (int i = 0; i < n; ++i) {
    const double u = 2 * std::numbers::pi * i / n;
    for (int side = 0; side < 2; ++side) {
      const double w = side == 0 ? 0.5 : -0.5;
      m.vertices.row(2 * i + side) << (1 + w * std::cos(u / 2)) * std::cos(u),
          (1 + w * std::cos(u / 2)) * std::sin(u), w * std::sin(u / 2);
    }
  }
  m.faces.resize(2 * n, 3);
  for (int i = 0; i < n; ++i) {
    const int t = 2 * i, b = 2 * i + 1;
    // After a full turn the half twist swaps the strip's two sides.
    const int t1 = i + 1 < n ? 2 * (i + 1) : 1, b1 = i + 1 < n ? 2 * (i + 1) + 1 : 0;
    m.faces.row(2 * i) << t, b, b1;
    m.faces.row(2 * i + 1) << t, b1, t1;
  }
  return m;
}

std::string off_of(const TriangleMesh& m) {
  std::ostringstream s;
  s.precision(17);
  s << "OFF\n" << m.num_vertices() << " " << m.num_faces() << " 0\n";
  for (Eigen::Index v = 0; v < m.num_vertices(); ++v)
    s << m.vertices(v, 0) << " " << m.vertices(v, 1) << " " << m.vertices(v, 2) << "\n";
  for (Eigen::Index f = 0; f < m.num_faces(); ++f)
    s << "3 " << m.faces(f, 0) << " " << m.faces(f, 1) << " " << m.faces(f, 2) << "\n";
  return s.str();
}

void reverse(Triangles& faces, Eigen::Index f) {
  std::swap(faces(f, 1), faces(f, 2));
}

TEST(Orientation, AConsistentMeshIsLeftAsItIs) {
  TriangleMesh m = make_icosphere(2);
  const Triangles before = m.faces;
  const OrientationResult r = orient_faces(m.faces);
  EXPECT_EQ(r.problem, OrientationResult::Problem::none);
  EXPECT_EQ(r.reoriented, 0);
  EXPECT_EQ(m.faces, before);
}

TEST(Orientation, ShuffledFacesComeBackAsTheMajorityOrientsThem) {
  // Any set of fewer than half the faces reversed is undone exactly; more than half, and the
  // rest is reversed instead (the orientation most faces have wins): consistent either way.
  const TriangleMesh sphere = make_icosphere(2);
  std::mt19937 rng(3);
  for (const double share : {0.1, 0.4, 0.7}) {
    TriangleMesh m = sphere;
    long long reversed = 0;
    for (Eigen::Index f = 0; f < m.num_faces(); ++f)
      if (std::uniform_real_distribution<double>(0, 1)(rng) < share) {
        reverse(m.faces, f);
        ++reversed;
      }
    ASSERT_GT(validate_mesh(m, "shuffled").misoriented_edges, 0);
    const OrientationResult r = orient_faces(m.faces);
    ASSERT_EQ(r.problem, OrientationResult::Problem::none);
    EXPECT_EQ(r.reoriented, std::min(reversed, m.num_faces() - reversed)) << share;
    EXPECT_EQ(validate_mesh(m, "oriented").misoriented_edges, 0);
    if (2 * reversed < m.num_faces()) {
      EXPECT_EQ(m.faces, sphere.faces);
    } else {
      EXPECT_LT(test::signed_volume(m), 0);  // the whole sphere, turned inside out
    }
  }
}

TEST(Orientation, ComponentsAreOrientedApart) {
  // Two icosahedra, one consistent, the other with 3 of its 20 faces reversed: only those 3 are
  // reversed back, and the first is untouched.
  TriangleMesh a = make_icosphere(0), b = make_icosphere(0);
  for (Eigen::Index f = 0; f < 3; ++f) reverse(b.faces, f);
  TriangleMesh both;
  both.vertices.resize(a.num_vertices() + b.num_vertices(), 3);
  both.vertices << a.vertices, b.vertices;
  both.faces.resize(a.num_faces() + b.num_faces(), 3);
  both.faces << a.faces, (b.faces.array() + int(a.num_vertices())).matrix();
  const OrientationResult r = orient_faces(both.faces);
  EXPECT_EQ(r.reoriented, 3);
  EXPECT_EQ(both.faces.topRows(a.num_faces()), a.faces);
  EXPECT_EQ(validate_mesh(both, "two").misoriented_edges, 0);
}

TEST(Orientation, AnEdgeInThreeFacesIsNonManifold) {
  Triangles fin(3, 3);
  fin << 0, 1, 2, 1, 0, 3, 0, 1, 4;
  const Triangles before = fin;
  const OrientationResult r = orient_faces(fin);
  EXPECT_EQ(r.problem, OrientationResult::Problem::non_manifold_edge);
  EXPECT_EQ(r.edge, (std::array<int, 2>{0, 1}));
  EXPECT_EQ(r.faces, (std::vector<Eigen::Index>{0, 1, 2}));
  EXPECT_EQ(fin, before);
}

TEST(Orientation, AMoebiusStripIsNonOrientable) {
  TriangleMesh m = moebius_strip(12);
  const Triangles before = m.faces;
  const OrientationResult r = orient_faces(m.faces);
  EXPECT_EQ(r.problem, OrientationResult::Problem::non_orientable);
  ASSERT_EQ(r.faces.size(), 2u);
  EXPECT_EQ(m.faces, before);
  // An annulus of the same quads, without the twist, orients (it needs no change).
  TriangleMesh annulus = m;
  annulus.faces.row(annulus.num_faces() - 2) << 22, 23, 1;
  annulus.faces.row(annulus.num_faces() - 1) << 22, 1, 0;
  EXPECT_EQ(orient_faces(annulus.faces).problem, OrientationResult::Problem::none);
}

TEST(Orientation, ReadMeshOrientsAFileAndSaysHowManyFacesItReversed) {
  TempDir dir;
  // CGAL's tet-shuffled.off: a tetrahedron listed with two of its faces reversed.
  const std::string path = dir.write("tet-shuffled.off",
                                     "OFF\n4 4 0\n0 0 0\n0 1 0\n1 1 0\n0 0 1\n"
                                     "3 0 1 2\n3 0 1 3\n3 0 2 3\n3 1 2 3\n");
  ReadReport report;
  const TriangleMesh m = read_mesh(path, &report);
  EXPECT_EQ(report.reoriented_faces, 2);
  const MeshReport v = validate_mesh(m, path);
  EXPECT_EQ(v.misoriented_edges, 0);
  EXPECT_EQ(v.boundary_loops, 0);
  // The spec loader records it in the report and says it in a note.
  const MeshSource src = load_mesh_spec(path);
  EXPECT_EQ(src.report.reoriented_faces, 2);
  ASSERT_EQ(src.notes.size(), 1u);
  EXPECT_NE(src.notes[0].find("reoriented 2 of 4 faces"), std::string::npos) << src.notes[0];
  // A consistent file: nothing reversed, nothing said.
  EXPECT_TRUE(load_mesh_spec(dir.write("tet.off", off_of(make_icosphere(0)))).notes.empty());
}

TEST(Orientation, ReadMeshNamesANonOrientableSurface) {
  TempDir dir;
  const std::string path = dir.write("moebius.off", off_of(moebius_strip(12)));
  try {
    read_mesh(path);
    FAIL() << "a Möbius strip loaded";
  } catch (const MeshError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(path + ": non-orientable mesh: face ", 0), 0u) << msg;
    EXPECT_NE(msg.find("Möbius"), std::string::npos) << msg;
    EXPECT_NE(msg.find("across edge ("), std::string::npos) << msg;
  }
}

}  // namespace
}  // namespace mcf
