// FlowObserver::stop: a caller that ends a flow early (the library's per-step callback) gets the
// flow as it stood after that step, recorded as a stop by the caller, not as a failure, and the
// steps before it are the steps an uninterrupted flow makes.

#include "config/flow_config.h"
#include "datasets/mesh_spec.h"
#include "flows/flow.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace mcf {
namespace {

FlowOutcome flow(int steps, const FlowObserver& observer = {}) {
  const FlowConfig c = flow_config_from_json(
      {{"mesh", "icosphere:level=2"}, {"steps", steps}, {"threads", 1}}, "test");
  return run_flow(c, load_mesh_spec(c.mesh, mesh_load_options(c)), observer);
}

TEST(FlowStop, EndsTheFlowAfterTheStepItIsAskedAtAndSaysSo) {
  const FlowOutcome whole = flow(3);
  int seen = -1;
  FlowObserver observer;
  observer.on_step = [&](int step, double, const Positions&) { seen = step; };
  observer.stop = [](int step) { return step == 3; };
  const FlowOutcome stopped = flow(10, observer);
  EXPECT_EQ(seen, 3);
  EXPECT_EQ(stopped.result["status"], "ok");
  EXPECT_EQ(stopped.result["stop"]["step"], 3);
  EXPECT_EQ(stopped.result["stop"]["reason"], "stopped by the caller");
  ASSERT_EQ(stopped.result["steps"].size(), 3u);
  // The same three steps as a flow of three: the stop changes nothing before it.
  EXPECT_EQ(stopped.final_mesh.vertices, whole.final_mesh.vertices);
}

TEST(FlowStop, AtStepZeroRunsNoStepAndKeepsTheInput) {
  FlowObserver observer;
  observer.stop = [](int) { return true; };
  const FlowOutcome o = flow(5, observer);
  EXPECT_EQ(o.result["stop"]["step"], 0);
  EXPECT_EQ(o.result["stop"]["reason"], "stopped by the caller");
  EXPECT_TRUE(o.result["steps"].empty());
  EXPECT_EQ(o.final_mesh.vertices, load_mesh_spec("icosphere:level=2").mesh.vertices);
}

}  // namespace
}  // namespace mcf
