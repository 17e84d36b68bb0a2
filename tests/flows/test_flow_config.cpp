#include "flows/config_reader.h"
#include "flows/flow_config.h"

#include <gtest/gtest.h>

namespace mcf {
namespace {

using nlohmann::json;

std::string error_of(const json& j) {
  try {
    flow_config_from_json(j, "cfg.json");
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(FlowConfig, DefaultsFilledAndRoundTrip) {
  const FlowConfig c = flow_config_from_json(json{{"mesh", "icosphere:level=3"}}, "cfg.json");
  EXPECT_EQ(c.flow, "mcf");
  EXPECT_EQ(c.solver.tolerance, 1e-10);  // cholmod default
  const FlowConfig again = flow_config_from_json(to_json(c), "again");
  EXPECT_EQ(to_json(again), to_json(c));
  const FlowConfig mg = flow_config_from_json(
      json{{"mesh", "x.off"}, {"basis", "octree"}, {"solver", {{"name", "multigrid"}}}}, "cfg.json");
  EXPECT_EQ(mg.solver.tolerance, 0.0);
}

TEST(FlowConfig, ErrorsNameFileAndKey) {
  EXPECT_NE(error_of(json::object()).find("cfg.json: mesh: missing"), std::string::npos);
  EXPECT_NE(error_of(json{{"mesh", "a"}, {"solver", {{"cycels", 2}}}}).find("cfg.json: solver.cycels: unknown key"),
            std::string::npos);
  EXPECT_NE(error_of(json{{"mesh", "a"}, {"solver", {{"cycles", "two"}}}}).find("solver.cycles: expected an integer"),
            std::string::npos);
  EXPECT_NE(error_of(json{{"mesh", "a"}, {"octree", {{"depth", 42}}}}).find("octree.depth: value 42 out of range"),
            std::string::npos);
  EXPECT_NE(error_of(json{{"mesh", "a"}, {"octree", {{"cubature", 4}}}}).find("octree.cubature"), std::string::npos);
  EXPECT_NE(error_of(json{{"mesh", "a"}, {"flow", "wilmore"}}).find("flow: unknown value"), std::string::npos);
  EXPECT_NE(error_of(json{{"mesh", "a"}, {"dt", -1.0}}).find("dt"), std::string::npos);
  EXPECT_NE(error_of(json{{"mesh", "a"}, {"solver", {{"name", "multigrid"}}}}).find("hierarchy"), std::string::npos);
  EXPECT_NE(error_of(json{{"mesh", "a"}, {"basis", "octree"}, {"octree", {{"tracking", "rebuilt"}}}, {"flow", "cmcf"}})
                .find("flow"),
            std::string::npos);
  // A lumped mass the octree basis would ignore while the result recorded it.
  EXPECT_NE(error_of(json{{"mesh", "a"}, {"basis", "octree"}, {"mass", "lumped"}})
                .find("cfg.json: mass: \"lumped\" applies to the hat basis only"),
            std::string::npos);
  EXPECT_NO_THROW(flow_config_from_json(json{{"mesh", "a"}, {"basis", "hat"}, {"mass", "lumped"}}, "cfg.json"));
}

}  // namespace
}  // namespace mcf
