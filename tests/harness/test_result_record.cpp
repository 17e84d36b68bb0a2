// One recorder (harness/result_record.h) completes the result of `mcfbench flow` and of each cell
// of `mcfbench run`: the same flow run both ways gives the same keys, and the same values wherever
// the value is not a clock, a memory reading or the cell's bookkeeping.

#include "harness/flow_folder.h"
#include "harness/runner.h"

#include "harness_test_util.h"

#include <set>
#include <string>

namespace mcf {
namespace {

using namespace mcf::test;
using nlohmann::json;

std::set<std::string> keys_of(const json& j) {
  std::set<std::string> keys;
  for (auto it = j.begin(); it != j.end(); ++it) keys.insert(it.key());
  return keys;
}

/// A step record without its clocks.
json untimed(json step) {
  step.erase("seconds");
  step.erase("setup_seconds");  // a rebuilt basis's step
  return step;
}

TEST(ResultRecord, FlowAndRunCellOfOneConfigHaveTheSameKeysAndValues) {
  const fs::path dir = fresh_dir("result_record");
  const json flow = {{"mesh", "icosphere:level=2"},
                     {"basis", "octree"},
                     {"octree", {{"depth", 5}}},
                     {"steps", 3},
                     {"dt", 1e-3},
                     {"threads", 1}};
  FlowRequest request;
  for (auto it = flow.begin(); it != flow.end(); ++it) request.settings.emplace_back(it.key(), *it);
  request.out = (dir / "flow").string();
  request.max_memory = "4G";
  ASSERT_EQ(run_flow_into_folder(request), 0);
  const json from_flow = read_json(dir / "flow" / "result.json");

  const ExperimentConfig e =
      parse_experiment_config({{"name", "same"}, {"defaults", flow}}, "same.json", false);
  RunOptions o;
  o.out_dir = (dir / "run").string();
  o.max_memory = "4G";
  ASSERT_EQ(run_experiment(e, o).ran, 1);
  const std::vector<fs::path> cells = result_files(dir / "run");
  ASSERT_EQ(cells.size(), 1u);
  json from_run = read_json(cells[0]);

  // The cell's bookkeeping is the only difference in keys.
  for (const char* own : {"cell", "study_config"}) {
    EXPECT_TRUE(from_run.contains(own)) << own;
    from_run.erase(own);
  }
  EXPECT_EQ(keys_of(from_flow), keys_of(from_run));
  for (const char* key : {"memory_budget", "peak_memory_scope", "contention", "timing",
                          "run_seconds", "memory_estimate", "environment"})
    EXPECT_TRUE(from_flow.contains(key)) << key;

  for (const char* same : {"schema", "status", "stop", "config", "mesh", "solver_name",
                           "environment", "memory_budget"})
    EXPECT_EQ(from_flow[same], from_run[same]) << same;
  // `flow` records its process's peak, a cell its own.
  EXPECT_EQ(from_flow["peak_memory_scope"], "process");
  EXPECT_EQ(from_flow["memory_budget"]["source"], from_run["memory_budget"]["source"]);
  // The estimates differ only in what the process held already when they were made.
  json a = from_flow["memory_estimate"], b = from_run["memory_estimate"];
  for (json* m : {&a, &b})
    for (const char* k : {"bytes", "resident_bytes"}) m->erase(k);
  EXPECT_EQ(a, b);
  json sa = from_flow["system"], sb = from_run["system"];
  sa.erase("setup_seconds");
  sb.erase("setup_seconds");
  EXPECT_EQ(sa, sb);
  ASSERT_EQ(from_flow["steps"].size(), 3u);
  ASSERT_EQ(from_run["steps"].size(), 3u);
  for (std::size_t i = 0; i < 3; ++i)
    EXPECT_EQ(untimed(from_flow["steps"][i]), untimed(from_run["steps"][i])) << "step " << i + 1;
  EXPECT_EQ(keys_of(from_flow["timing"]), keys_of(from_run["timing"]));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace mcf
