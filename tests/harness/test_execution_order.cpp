// The order `run` walks the cells in: repetitions interleaved in seeded shuffled rounds.
#include "config/config_reader.h"
#include "harness/runner.h"

#include <gtest/gtest.h>

#include <set>
#include <vector>

namespace mcf {
namespace {

using nlohmann::json;

ExperimentConfig config(int repetitions, const json& extra = json::object()) {
  json j = {{"name", "order"},
            {"defaults", {{"mesh", "icosphere:level=1"}, {"steps", 1}}},
            {"axes", {{"dt", {1e-3, 2e-3, 3e-3, 4e-3, 5e-3, 6e-3}}}},
            {"repetitions", repetitions}};
  j.update(extra);
  return parse_experiment_config(j, "order.json", false);
}

/// Plans without meshes: execution_order reads only the cells.
std::vector<CellPlan> plans_of(const ExperimentConfig& e) {
  std::vector<CellPlan> plans;
  for (const Cell& c : e.cells) plans.push_back(CellPlan{c, "", "", "", "", ""});
  return plans;
}

TEST(ExecutionOrder, RoundsHoldEveryCellOnceInAShuffledOrder) {
  const ExperimentConfig e = config(3);
  const auto plans = plans_of(e);
  const auto order = execution_order(e, plans);
  ASSERT_EQ(order.size(), 18u);
  std::vector<std::vector<double>> rounds(3);
  for (std::size_t k = 0; k < order.size(); ++k) {
    const Cell& c = plans[order[k]].cell;
    EXPECT_EQ(c.repetition, int(k / 6)) << "round " << k / 6 << " holds only its repetition";
    rounds[k / 6].push_back(c.flow.dt);
  }
  for (const auto& r : rounds) EXPECT_EQ(std::set<double>(r.begin(), r.end()).size(), 6u);
  // Not expansion order, and the rounds are shuffled apart (seeded by the round).
  EXPECT_NE(rounds[0], (std::vector<double>{1e-3, 2e-3, 3e-3, 4e-3, 5e-3, 6e-3}));
  EXPECT_NE(rounds[0], rounds[1]);
  // Fixed by the seed: the same again; another seed, another order.
  EXPECT_EQ(execution_order(e, plans), order);
  const ExperimentConfig other = config(3, {{"order_seed", 7}});
  EXPECT_NE(execution_order(other, plans_of(other)), order);
}

TEST(ExecutionOrder, ExpansionOrderWithoutInterleavingOrRepetitions) {
  for (const ExperimentConfig& e : {config(3, {{"interleave", false}}), config(1)}) {
    const auto plans = plans_of(e);
    const auto order = execution_order(e, plans);
    ASSERT_EQ(order.size(), plans.size());
    for (std::size_t k = 0; k < order.size(); ++k) EXPECT_EQ(order[k], k);
  }
}

TEST(ExecutionOrder, AShardWalksOnlyItsCells) {
  const ExperimentConfig e = config(2);
  const auto plans = plans_of(e);
  std::set<std::size_t> all;
  for (int i = 0; i < 3; ++i)
    for (std::size_t k : execution_order(e, plans, i, 3)) {
      EXPECT_EQ(plans[k].cell.index % 3, i);
      EXPECT_TRUE(all.insert(k).second);
    }
  EXPECT_EQ(all.size(), plans.size());
}

TEST(ExecutionOrder, BadKeysAreNamed) {
  EXPECT_THROW(config(2, {{"interleave", "yes"}}), ConfigError);
  EXPECT_THROW(config(2, {{"order_seed", -1}}), ConfigError);
}

}  // namespace
}  // namespace mcf
