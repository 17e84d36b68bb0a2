// $MCFBENCH_PLANTED_SLOWDOWN (flows/planted_slowdown.h): each step (or, with
// $MCFBENCH_PLANTED_PHASE=update, each update) lasts (1 + f) times its own work, the result records
// f, the phase and each step's wait, and a malformed value stops the flow naming the variable.

#include "harness_test_util.h"

namespace mcf {
namespace {

using namespace mcf::test;

TEST(PlantedSlowdown, StepsLastOnePlusFTimesTheirWorkAndTheResultSaysSo) {
  const fs::path dir = fresh_dir("planted_slowdown");
  Command c = mcfbench("flow --mesh icosphere:level=2 --steps 3 --out plain", dir);
  ASSERT_EQ(c.status, 0) << c.err;
  EXPECT_FALSE(
      read_json(dir / "plain" / "result.json")["environment"].contains("planted_slowdown"));
  c = mcfbench("flow --mesh icosphere:level=2 --steps 3 --out slowed", dir,
               "MCFBENCH_PLANTED_SLOWDOWN=1 ");
  ASSERT_EQ(c.status, 0) << c.err;
  const nlohmann::json r = read_json(dir / "slowed" / "result.json");
  EXPECT_EQ(r["environment"]["planted_slowdown"], 1.0);
  EXPECT_EQ(r["environment"]["planted_phase"], "step");
  ASSERT_EQ(r["steps"].size(), 3u);
  for (const auto& s : r["steps"]) {
    // The phases are timed inside the step's own work, which the delay then doubles: an
    // inequality that holds whatever the machine's speed.
    const auto& t = s["seconds"];
    const double work =
        t["update"].get<double>() + t["solve"].get<double>() + t["evaluate"].get<double>();
    EXPECT_GE(t["total"].get<double>(), 2 * work) << s.dump();
    EXPECT_GT(t["planted"].get<double>(), 0.0) << s.dump();  // the wait, recorded
  }
  // Held in a named value: a range-for over a member of a temporary reads it after its end.
  const nlohmann::json plain = read_json(dir / "plain" / "result.json");
  for (const auto& s : plain["steps"]) EXPECT_FALSE(s["seconds"].contains("planted")) << s.dump();
  c = mcfbench("flow --mesh icosphere:level=2 --steps 3 --out bad", dir,
               "MCFBENCH_PLANTED_SLOWDOWN=lots ");
  EXPECT_NE(c.status, 0);
  EXPECT_NE(c.err.find("MCFBENCH_PLANTED_SLOWDOWN=lots"), std::string::npos) << c.err;
}

TEST(PlantedSlowdown, PlantedInTheUpdateTheResultNamesThePhase) {
  const fs::path dir = fresh_dir("planted_update");
  Command c = mcfbench("flow --mesh icosphere:level=2 --steps 2 --out slowed", dir,
                       "MCFBENCH_PLANTED_SLOWDOWN=0.5 MCFBENCH_PLANTED_PHASE=update ");
  ASSERT_EQ(c.status, 0) << c.err;
  const nlohmann::json r = read_json(dir / "slowed" / "result.json");
  EXPECT_EQ(r["environment"]["planted_slowdown"], 0.5);
  EXPECT_EQ(r["environment"]["planted_phase"], "update");
  ASSERT_EQ(r["steps"].size(), 2u);
  for (const auto& s : r["steps"]) {
    // The wait lies inside the update's own time (each update call lasts its work plus the
    // wait), so the update's seconds hold the planted seconds: inequalities that hold whatever
    // the machine's speed.
    const auto& t = s["seconds"];
    EXPECT_GT(t["planted"].get<double>(), 0.0) << s.dump();
    EXPECT_GE(t["update"].get<double>(), t["planted"].get<double>()) << s.dump();
    EXPECT_GE(t["total"].get<double>(), t["update"].get<double>()) << s.dump();
  }
  c = mcfbench("flow --mesh icosphere:level=2 --steps 2 --out bad", dir,
               "MCFBENCH_PLANTED_SLOWDOWN=0.5 MCFBENCH_PLANTED_PHASE=solve ");
  EXPECT_NE(c.status, 0);
  EXPECT_NE(c.err.find("MCFBENCH_PLANTED_PHASE=solve"), std::string::npos) << c.err;
  EXPECT_FALSE(fs::exists(dir / "bad" / "result.json"));
}

}  // namespace
}  // namespace mcf
