// octree.refine_input with the hat basis: the flow of the once-refined mesh, output at the input's
// vertices, is exactly the hat flow of the 1-to-4 split mesh restricted to its first vertices.
#include "flow_test_util.h"

#include "config/flow_config.h"
#include "datasets/subdivide.h"

#include <gtest/gtest.h>

namespace mcf {
namespace {

using nlohmann::json;

TEST(RefineInput, HatFlowOfTheSplitMeshAtTheInputsVertices) {
  for (const char* solver : {"cholmod", "multigrid"}) {
    json j = {{"mesh", "torus:n_major=48,n_minor=16"},
              {"basis", "hat"},
              {"steps", 3},
              {"dt", 1e-4},
              {"solver", {{"name", solver}, {"tolerance", 1e-13}}}};
    if (std::string(solver) == "multigrid") j["solver"]["cycles"] = 30;
    json refined = j;
    refined["octree"]["refine_input"] = true;
    const FlowConfig a = flow_config_from_json(refined, "test"),
                     b = flow_config_from_json(j, "test");
    const MeshSource source = load_mesh_spec(a.mesh);
    MeshSource split = source;
    split.mesh = subdivide_midpoint(source.mesh);
    const FlowOutcome on_input = run_flow(a, source), on_split = run_flow(b, split);
    const Eigen::Index n = source.mesh.num_vertices();
    ASSERT_EQ(on_input.final_mesh.vertices.rows(), n) << solver;
    ASSERT_EQ(on_input.final_mesh.faces, source.mesh.faces) << solver;
    const Positions expected = on_split.final_mesh.vertices.topRows(n);
    EXPECT_LT((on_input.final_mesh.vertices - expected).norm() / expected.norm(), 1e-9) << solver;
    // And it moved: a different flow from the input mesh's own.
    const FlowOutcome plain = run_flow(b, source);
    EXPECT_GT((plain.final_mesh.vertices - expected).norm() / expected.norm(), 1e-7) << solver;
  }
}

}  // namespace
}  // namespace mcf
