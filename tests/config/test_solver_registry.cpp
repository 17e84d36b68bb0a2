#include "config/solver_registry.h"

#include "config/flow_config.h"

#include <gtest/gtest.h>

namespace mcf {
namespace {

using nlohmann::json;

// CG's preconditioner is CG's own option too: "jacobi" unless set, and where it is the multigrid
// CG needs the basis's hierarchy and runs across ranks, as the multigrid solver does.
TEST(SolverRegistry, ThePreconditionerIsCgsOption) {
  SolverConfig pcg;
  pcg.name = "pcg";
  EXPECT_EQ(preconditioner_name(pcg), "jacobi");
  EXPECT_FALSE(needs_hierarchy(pcg));
  EXPECT_FALSE(runs_across_ranks(pcg));
  const SolverConfig read =
      flow_config_from_json(
          json{{"mesh", "x"}, {"solver", {{"name", "pcg"}, {"preconditioner", "multigrid"}}}}, "t")
          .solver;
  EXPECT_EQ(preconditioner_name(read), "multigrid");
  EXPECT_TRUE(needs_hierarchy(read));
  EXPECT_TRUE(runs_across_ranks(read));
  pcg.params["preconditioner"] = "ichol";
  EXPECT_EQ(preconditioner_name(pcg), "ichol");
  EXPECT_FALSE(needs_hierarchy(pcg));
}

}  // namespace
}  // namespace mcf
