#include "config/multigrid_params.h"

#include "config/flow_config.h"
#include "config/solver_registry.h"

#include <gtest/gtest.h>

namespace mcf {
namespace {

using nlohmann::json;

// One default per key: the multigrid's options read from a config that sets none of them, built
// in code or read from JSON, are the numerics' own defaults field by field.
TEST(MultigridParams, TheDefaultsAreTheNumerics) {
  const MultigridOptions cycle{};
  const StallFallbackOptions guard{};
  const SolverConfig in_code{};
  const SolverConfig read =
      flow_config_from_json(json{{"mesh", "x"}, {"solver", {{"name", "multigrid"}}}}, "t").solver;
  for (const SolverConfig* c : {&in_code, &read}) {
    const MultigridOptions o = multigrid_options(*c);
    EXPECT_EQ(o.cycle, cycle.cycle);
    EXPECT_EQ(o.cycles, cycle.cycles);
    EXPECT_EQ(o.pre_smooth, cycle.pre_smooth);
    EXPECT_EQ(o.post_smooth, cycle.post_smooth);
    EXPECT_EQ(o.galerkin_by_term, cycle.galerkin_by_term);
    EXPECT_EQ(o.mixed_precision, cycle.mixed_precision);
    EXPECT_EQ(o.galerkin_refresh, cycle.galerkin_refresh);
    const StallFallbackOptions f = stall_fallback_options(*c);
    EXPECT_EQ(f.stall_ratio, guard.stall_ratio);
    EXPECT_EQ(f.residual_bound, guard.residual_bound);
    EXPECT_EQ(f.bound_smooth_steps, guard.bound_smooth_steps);
    EXPECT_EQ(f.tolerance, guard.tolerance);
    EXPECT_EQ(f.direct_after, guard.direct_after);
    EXPECT_EQ(f.max_iterations, guard.max_iterations);
  }
  // The config read fills in every option's value; one written in code holds none until set.
  EXPECT_EQ(read.params.at("cycles"), cycle.cycles);
  EXPECT_TRUE(in_code.params.empty());
}

// What a config sets is what the solver gets: every option at a value other than its default.
TEST(MultigridParams, ReadBackWhatTheConfigSets) {
  const json solver = {{"name", "multigrid"},
                       {"cycle", "V"},
                       {"cycles", 3},
                       {"smooth", 2},
                       {"galerkin_by_term", true},
                       {"precision", "mixed"},
                       {"galerkin_refresh", 4},
                       {"stall_ratio", 0.5},
                       {"residual_bound", 1e-6},
                       {"bound_smooth_steps", true},
                       {"fallback_tolerance", 1e-8},
                       {"direct_after", 7},
                       {"max_iterations", 20}};
  const FlowConfig c = flow_config_from_json(json{{"mesh", "x"}, {"solver", solver}}, "t");
  const MultigridOptions o = multigrid_options(c.solver);
  EXPECT_EQ(o.cycle, MultigridCycle::V);
  EXPECT_EQ(o.cycles, 3);
  EXPECT_EQ(o.pre_smooth, 2);
  EXPECT_EQ(o.post_smooth, 2);
  EXPECT_TRUE(o.galerkin_by_term);
  EXPECT_TRUE(o.mixed_precision);
  EXPECT_EQ(o.galerkin_refresh, 4);
  const StallFallbackOptions f = stall_fallback_options(c.solver);
  EXPECT_EQ(f.stall_ratio, 0.5);
  EXPECT_EQ(f.residual_bound, 1e-6);
  EXPECT_TRUE(f.bound_smooth_steps);
  EXPECT_EQ(f.tolerance, 1e-8);
  EXPECT_EQ(f.direct_after, 7);
  EXPECT_EQ(f.max_iterations, 20);
  // And the record holds them under their keys, as before they lived in the params.
  const json recorded = to_json(c)["solver"];
  for (const auto& [key, value] : solver.items()) EXPECT_EQ(recorded.at(key), value) << key;
}

// A config that sets none of them records the keys every earlier result has, so that its cells
// keep their config keys: the cycle's first three under every solver, the guard's under the
// multigrid only, the options added later (by_term, precision, refresh) nowhere.
TEST(MultigridParams, ADefaultRecordKeepsTheKeysOfEarlierResults) {
  for (const char* name : {"multigrid", "cholmod"}) {
    const json recorded = to_json(
        flow_config_from_json(json{{"mesh", "x"}, {"solver", {{"name", name}}}}, "t"))["solver"];
    for (const char* key : {"cycle", "cycles", "smooth"})
      EXPECT_TRUE(recorded.contains(key)) << name << " " << key;
    for (const char* key : {"galerkin_by_term", "precision", "galerkin_refresh"})
      EXPECT_FALSE(recorded.contains(key)) << name << " " << key;
    EXPECT_EQ(recorded.contains("stall_ratio"), std::string(name) == "multigrid") << name;
  }
}

// Every solver option a component reads through param_value is found by its leaf.
TEST(MultigridParams, EveryOptionIsASolverOption) {
  for (const auto* options : {&multigrid_cycle_options(), &stall_guard_options()})
    for (const OptionSpec& o : *options)
      EXPECT_NO_THROW(solver_option(split_key(o.key).second)) << o.key;
  EXPECT_EQ(solver_option("petsc_options").fallback, "");
  EXPECT_THROW(solver_option("omega_typo"), std::logic_error);
}

}  // namespace
}  // namespace mcf
