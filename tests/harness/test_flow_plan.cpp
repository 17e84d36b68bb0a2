// The four steps of one flow (harness/flow_plan.h): each refuses what it should, naming what the
// plan names, and the mesh the plan loads is the spec's.

#include "harness/flow_plan.h"

#include "config/config_reader.h"

#include <gtest/gtest.h>

#include <string>

namespace mcf {
namespace {

template <class Error, class F>
std::string message_of(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "nothing thrown";
  return "";
}

TEST(FlowPlan, PrepareParsesTheSpecOnceAndRefusesABadOne) {
  FlowConfig c;
  c.mesh = "torus:R=0.9,n_major=20";
  const FlowPlan plan = prepare_flow(c);
  EXPECT_EQ(plan.what, c.mesh);
  EXPECT_EQ(plan.mesh.spec, c.mesh);
  EXPECT_EQ(plan.mesh.kind, "torus");
  EXPECT_EQ(plan.mesh.parameters.at("R"), 0.9);
  EXPECT_EQ(prepare_flow(c, "cell 3").what, "cell 3");

  c.mesh = "torus:foo=1";
  const std::string m = message_of<MeshError>([&] { prepare_flow(c, "cell 3"); });
  EXPECT_NE(m.find("torus:foo=1"), std::string::npos) << m;
  EXPECT_NE(m.find("unknown key 'foo'"), std::string::npos) << m;
}

TEST(FlowPlan, EstimateRefusesOverTheBudgetBeforeLoading) {
  FlowConfig c;
  c.mesh = "sphere:vertices=50000000";  // never generated: the estimate refuses it first
  const FlowPlan plan = prepare_flow(c, "cell 7 (sphere)");
  const std::string m =
      message_of<MemoryLimitError>([&] { estimate_flow(plan, memory_budget("1G")); });
  EXPECT_NE(m.find("cell 7 (sphere)"), std::string::npos) << m;
  EXPECT_NE(m.find("--max-memory"), std::string::npos) << m;
  const MemoryEstimate e = estimate_flow(plan, memory_budget("none"));
  EXPECT_GT(e.dimension, 1e7);
}

TEST(FlowPlan, TheLoadedMeshIsTheSpecsAndIsCheckedAgainstTheConfig) {
  FlowConfig c;
  c.mesh = "open_cylinder";
  c.normalize_area = false;
  const FlowPlan plan = prepare_flow(c);
  const MeshSource mesh = load_flow_mesh(plan);
  const MeshSource direct = load_mesh_spec(c.mesh, mesh_load_options(c));
  EXPECT_TRUE(mesh.mesh.vertices == direct.mesh.vertices);
  EXPECT_TRUE(mesh.mesh.faces == direct.mesh.faces);
  const MemoryEstimate loaded = check_loaded_flow(plan, mesh, memory_budget("none"));
  EXPECT_GT(loaded.dimension, 0);

  // An open surface cannot keep unit area: refused once the mesh shows its boundary.
  FlowPlan normalized = plan;
  normalized.config.normalize_area = true;
  const std::string m =
      message_of<ConfigError>([&] { check_loaded_flow(normalized, mesh, memory_budget("none")); });
  EXPECT_NE(m.find("open_cylinder"), std::string::npos) << m;
  EXPECT_NE(m.find("normalize_area"), std::string::npos) << m;
}

}  // namespace
}  // namespace mcf
