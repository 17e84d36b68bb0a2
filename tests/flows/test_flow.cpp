// Flows on meshes as they come: a mesh whose every vertex lies on its held boundary has nothing
// free to move, and every solver completes its flow with the mesh unchanged (none is asked to
// factorize or cycle on an empty system, which each used to report as a singular flow); the
// octree basis flows a mesh with zero-area faces; repair_degenerate removes them for the hat
// basis; unit-area normalisation of an open surface is refused saying what to run instead.

#include "../core/temp_dir.h"
#include "config/config_reader.h"
#include "config/flow_config.h"
#include "datasets/mesh_spec.h"
#include "flows/flow.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <string>

namespace mcf {
namespace {

using test::TempDir;

FlowOutcome flow(const nlohmann::json& j) {
  const FlowConfig c = flow_config_from_json(j, "test");
  return run_flow(c, load_mesh_spec(c.mesh, mesh_load_options(c)));
}

// CGAL's quad.off: one quad, fanned into two triangles; all four vertices on the boundary.
const char* kQuad = "OFF\n4 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n4 0 1 2 3\n";

TEST(Flow, NothingFreeToMoveCompletesWithTheMeshUnchangedWithEverySolver) {
  TempDir dir;
  const std::string quad = dir.write("quad.off", kQuad);
  const TriangleMesh input = load_mesh_spec(quad).mesh;
  for (const nlohmann::json& solver :
       {nlohmann::json{{"name", "cholmod"}}, nlohmann::json{{"name", "multigrid"}},
        nlohmann::json{{"name", "pcg"}}, nlohmann::json{{"name", "dense"}}}) {
    for (const char* integrator : {"semi-implicit", "bdf2", "taylor2"}) {
      const FlowOutcome o = flow({{"mesh", quad},
                                  {"basis", "hat"},
                                  {"solver", solver},
                                  {"integrator", integrator},
                                  {"steps", 3}});
      const std::string what = solver.dump() + " " + integrator;
      EXPECT_EQ(o.result["status"], "ok") << what << o.result["stop"].dump();
      EXPECT_EQ(o.result["stop"]["reason"], "completed") << what;
      EXPECT_EQ(o.result["stop"]["step"], 3) << what;
      EXPECT_EQ(o.result["system"]["free_functions"], 0) << what;
      ASSERT_EQ(o.result["notes"].size(), 1u) << what;
      EXPECT_NE(o.result["notes"][0].get<std::string>().find("nothing free to move"),
                std::string::npos)
          << what;
      EXPECT_EQ(o.result["steps"].size(), 3u) << what;
      EXPECT_EQ(o.result["steps"][0]["solver"]["status"], "converged") << what;
      EXPECT_EQ(o.final_mesh.vertices, input.vertices) << what;
    }
  }
}

TEST(Flow, AMeshWithFreeFunctionsRecordsTheirCountAndNoNote) {
  const FlowOutcome o = flow({{"mesh", "open_cylinder:n_around=16,n_along=4"}, {"steps", 1}});
  EXPECT_EQ(o.result["status"], "ok");
  EXPECT_EQ(o.result["system"]["free_functions"], 16 * 3);  // the 3 inner rings
  EXPECT_FALSE(o.result.contains("notes"));
}

// A unit square with a zero-area cap on its bottom edge (the face 0 1 4, vertex 4 the edge's
// midpoint), lifted into a tent so that the flow has something to do.
const char* kTentWithCap =
    "OFF\n6 6 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 0 0\n0.5 0.5 0.5\n"
    "3 0 4 5\n3 4 1 5\n3 1 2 5\n3 2 3 5\n3 3 0 5\n3 0 1 4\n";

TEST(Flow, ZeroAreaFacesAreKeptByTheOctreeRefusedByTheHatBasisOrCollapsedOnRequest) {
  TempDir dir;
  const std::string tent = dir.write("tent.off", kTentWithCap);
  // The hat basis refuses them, naming the face and the two ways on.
  try {
    flow({{"mesh", tent}, {"basis", "hat"}, {"steps", 1}});
    FAIL() << "the hat basis took a zero-area face";
  } catch (const MeshError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("face 5 is degenerate"), std::string::npos) << msg;
    EXPECT_NE(msg.find("--repair-degenerate"), std::string::npos) << msg;
    EXPECT_NE(msg.find("--basis octree"), std::string::npos) << msg;
  }
  // The octree basis flows the mesh as it is.
  const FlowOutcome octree =
      flow({{"mesh", tent}, {"basis", "octree"}, {"octree", {{"depth", 5}}}, {"steps", 2}});
  EXPECT_EQ(octree.result["status"], "ok") << octree.result["stop"].dump();
  EXPECT_EQ(octree.result["mesh"]["degenerate_faces"], 1);
  EXPECT_EQ(octree.result["mesh"]["faces"], 6);
  EXPECT_EQ(octree.result["mesh"]["notes"].size(), 1u);
  // repair_degenerate removes the cap for the hat basis (its longest edge is on the boundary, so
  // it is collapsed), and says so in the config and mesh.
  const FlowOutcome hat =
      flow({{"mesh", tent}, {"basis", "hat"}, {"repair_degenerate", true}, {"steps", 2}});
  EXPECT_EQ(hat.result["status"], "ok") << hat.result["stop"].dump();
  EXPECT_EQ(hat.result["config"]["repair_degenerate"], true);
  EXPECT_EQ(hat.result["mesh"]["repaired_faces"], 1);
  EXPECT_EQ(hat.result["mesh"]["faces"], 4);
  EXPECT_EQ(hat.final_mesh.num_faces(), 4);
  // Left unset, the key stays out of the config (so cell keys of earlier runs still match).
  EXPECT_FALSE(octree.result["config"].contains("repair_degenerate"));
}

TEST(Flow, UnitAreaOnAnOpenSurfaceIsRefusedSayingWhatToRunInstead) {
  try {
    flow({{"mesh", "open_cylinder:n_around=16,n_along=4"}, {"normalize_area", true}});
    FAIL() << "normalize_area on an open surface";
  } catch (const ConfigError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("2 boundary loop(s)"), std::string::npos) << msg;
    EXPECT_NE(msg.find("leave out --normalize-area"), std::string::npos) << msg;
    EXPECT_NE(msg.find("close its holes"), std::string::npos) << msg;
  }
}

}  // namespace
}  // namespace mcf
