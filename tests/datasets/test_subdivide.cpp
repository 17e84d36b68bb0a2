#include "datasets/generators.h"
#include "datasets/subdivide.h"
#include "datasets/validate.h"
#include "test_util.h"

#include <gtest/gtest.h>

namespace mcf {
namespace {

TEST(Subdivide, CountsAndAreaOfAFlatMesh) {
  const TriangleMesh m = make_cubical_spiral(2, 32, 3);  // planar pieces: area exactly kept
  const TriangleMesh s = subdivide_midpoint(m);
  EXPECT_EQ(s.num_faces(), 4 * m.num_faces());
  const MeshReport a = validate_mesh(m, "m"), b = validate_mesh(s, "s");
  // V' = V + E; E from Euler: E = V + F - χ.
  EXPECT_EQ(s.num_vertices(),
            m.num_vertices() + (m.num_vertices() + m.num_faces() - a.euler_characteristic));
  EXPECT_NEAR(b.area, a.area, 1e-10 * a.area);
  EXPECT_EQ(b.boundary_loops, a.boundary_loops);
  EXPECT_EQ(b.genus, a.genus);
  EXPECT_EQ(b.misoriented_edges, 0);
}

TEST(Subdivide, KeepsOriginalVerticesAndTopology) {
  const TriangleMesh m = make_torus(1.0, 0.3, 16, 8);
  const TriangleMesh s = subdivide_midpoint(m);
  EXPECT_EQ(s.vertices.topRows(m.num_vertices()), m.vertices);
  const MeshReport r = validate_mesh(s, "s");
  EXPECT_TRUE(r.closed());  // midpoints shared: no cracks
  EXPECT_EQ(r.genus, 1);
  EXPECT_GT(test::signed_volume(s), 0);
  EXPECT_NEAR(r.area, surface_area(m), 1e-9);  // midpoints lie on the flat parent faces
}

TEST(Subdivide, ToTargetFaces) {
  const TriangleMesh m = make_icosphere(0);
  EXPECT_EQ(subdivide_to_faces(m, 20).num_faces(), 20);
  EXPECT_EQ(subdivide_to_faces(m, 21).num_faces(), 80);
  EXPECT_EQ(subdivide_to_faces(m, 1000).num_faces(), 1280);
  EXPECT_EQ(subdivide_to_faces(TriangleMesh{}, 1000).num_faces(), 0);  // no endless loop
}

}  // namespace
}  // namespace mcf
