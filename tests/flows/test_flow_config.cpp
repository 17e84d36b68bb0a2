#include "config/config_reader.h"
#include "config/config_schema.h"
#include "config/flow_config.h"
#include "config/multigrid_params.h"
#include "core/parallel.h"
#include "datasets/mesh_spec.h"
#include "flows/flow.h"
#include "solvers/blas_threads.h"
#include "solvers/multigrid_fallback.h"

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
      json{{"mesh", "x.off"}, {"basis", "octree"}, {"solver", {{"name", "multigrid"}}}},
      "cfg.json");
  EXPECT_EQ(mg.solver.tolerance, 0.0);
  // The residual bound's one default: a config built in code, the config reader and the solver.
  EXPECT_EQ(stall_fallback_options(FlowConfig{}.solver).residual_bound, kDefaultResidualBound);
  EXPECT_EQ(stall_fallback_options(mg.solver).residual_bound, kDefaultResidualBound);
  EXPECT_EQ(mg.solver.params.at("residual_bound"), kDefaultResidualBound);
  EXPECT_EQ(StallFallbackOptions{}.residual_bound, kDefaultResidualBound);
}

// octree.stabilization_weight left out is the solver's, filled in when the config is read: the
// cycles' 0.5 for the iterative solvers, 1e-6 (definite only) for the direct ones; a weight set
// stays; where no term is added (the hat basis, the paper's system) the 0.5 recorded before the
// weight became the solver's.
TEST(FlowConfig, StabilizationWeightIsTheSolversUnlessSet) {
  const auto weight = [](const json& j) {
    return flow_config_from_json(j, "cfg.json").octree.stabilization_weight;
  };
  const auto octree = [](const json& solver, const json& options) {
    return json{{"mesh", "x.off"}, {"basis", "octree"}, {"solver", solver}, {"octree", options}};
  };
  EXPECT_EQ(weight(octree(json::object(), json::object())), 1e-6);  // CHOLMOD, the default
  EXPECT_EQ(weight(octree({{"name", "dense"}}, json::object())), 1e-6);
  EXPECT_EQ(weight(octree({{"name", "multigrid"}}, json::object())), 0.5);
  EXPECT_EQ(weight(octree({{"name", "pcg"}}, json::object())), 0.5);
  EXPECT_EQ(weight(octree(json::object(), {{"stabilization_weight", 0.05}})), 0.05);
  EXPECT_EQ(weight(octree({{"name", "multigrid"}}, {{"stabilization_weight", 0}})), 0.0);
  EXPECT_EQ(weight(json{{"mesh", "x.off"}, {"basis", "hat"}}), 0.5);
  EXPECT_EQ(weight(octree(json::object(), {{"stabilization", "none"}})), 0.5);
  // What ran is what is recorded, and reading the record again changes nothing.
  const FlowConfig c = flow_config_from_json(octree(json::object(), json::object()), "cfg.json");
  EXPECT_EQ(to_json(c)["octree"]["stabilization_weight"], 1e-6);
  EXPECT_EQ(to_json(flow_config_from_json(to_json(c), "again")), to_json(c));
  EXPECT_NE(error_of(octree(json::object(), {{"stabilization_weight", -1}}))
                .find("cfg.json: octree.stabilization_weight"),
            std::string::npos);
}

// One default per key: the struct's member initializers (what the reader starts from) and the
// schema's fallback (what --help, docs/flow.md, to_json's when_set and the refusals compare with)
// agree for every option.
TEST(FlowConfig, TheStructsDefaultsAreTheSchemasDefaults) {
  const FlowConfig c{};
  for (const OptionSpec& o : flow_config_schema()) EXPECT_EQ(o.get(c), o.fallback) << o.key;
}

// A key of a component not in use is refused, naming the key, the component that reads it and
// the one in use; nothing rewrites another component's option without a word.
TEST(FlowConfig, KeysOfComponentsNotInUseAreRefused) {
  const auto with = [](const json& solver) { return json{{"mesh", "a"}, {"solver", solver}}; };
  const auto refused = [&](const json& solver, const std::string& what) {
    const std::string e = error_of(with(solver));
    EXPECT_NE(e.find(what), std::string::npos) << solver.dump() << ": " << e;
  };
  refused({{"name", "cholmod"}, {"cycles", 7}},
          "cfg.json: solver.cycles: applies to solver \"multigrid\"");
  refused({{"name", "cholmod"}, {"cycles", 7}}, "the solver is \"cholmod\"");
  refused({{"name", "cholmod"}, {"cycle", "V"}}, "solver.cycle: \"V\" applies to a multigrid");
  refused({{"name", "pcg"}, {"smooth", 3}}, "solver.smooth: applies to a multigrid");
  refused({{"name", "pcg"}, {"smooth", 3}}, "the solver is \"pcg\" with preconditioner \"jacobi\"");
  // CG's multigrid preconditioner is one cycle an iteration, whatever cycles says.
  refused({{"name", "pcg"}, {"preconditioner", "multigrid"}, {"cycles", 2}},
          "solver.cycles: applies to solver \"multigrid\"");
  refused({{"name", "multigrid"}, {"preconditioner", "ichol"}},
          "solver.preconditioner: \"ichol\" applies to solver \"pcg\" only");
  // A solver row's own options (recorded only where it runs) are refused elsewhere too.
  refused({{"name", "cholmod"}, {"stall_ratio", 0.5}},
          "solver.stall_ratio: applies to solver \"multigrid\" only");
  refused({{"name", "petsc"}, {"residual_bound", 1e-3}}, "solver.residual_bound");
  // The octree basis's options under the hat basis; refine_input is read by both, and the
  // weight's inert value (what a hat config records) is no request.
  const auto basis_refusal = [](const json& octree) {
    return error_of(json{{"mesh", "a"}, {"basis", "hat"}, {"octree", octree}});
  };
  EXPECT_NE(basis_refusal({{"depth", 6}})
                .find("cfg.json: octree.depth: applies to basis \"octree\" only, the basis is "
                      "\"hat\""),
            std::string::npos);
  EXPECT_NE(basis_refusal({{"stabilization", "none"}}).find("octree.stabilization: \"none\""),
            std::string::npos);
  EXPECT_NE(basis_refusal({{"stabilization_weight", 2.0}}).find("octree.stabilization_weight"),
            std::string::npos);
  EXPECT_NE(basis_refusal({{"tracking", "rebuilt"}}).find("octree.tracking"), std::string::npos);
  EXPECT_EQ(basis_refusal({{"refine_input", true}}), "");
  EXPECT_EQ(basis_refusal({{"stabilization_weight", 0.5}}), "");
  EXPECT_EQ(basis_refusal({{"depth", 8}}), "");  // the default
  EXPECT_EQ(error_of(json{{"mesh", "a"}, {"basis", "octree"}, {"octree", {{"depth", 6}}}}), "");
  // --frozen: the two-step integrators' operators at X_n; the others read nothing of it.
  EXPECT_NE(error_of(json{{"mesh", "a"}, {"extrapolate", false}})
                .find("cfg.json: extrapolate: applies to the two-step integrators (crank-nicolson, "
                      "bdf2) only, the integrator is \"semi-implicit\""),
            std::string::npos);
  EXPECT_EQ(error_of(json{{"mesh", "a"}, {"integrator", "bdf2"}, {"extrapolate", false}}), "");
  refused({{"name", "pcg"}, {"direct_after", 3}}, "solver.direct_after");
  // Taken where they are read, and at their defaults anywhere.
  for (const json& solver :
       {json{{"name", "multigrid"}, {"cycle", "V"}, {"cycles", 3}, {"smooth", 2}},
        json{{"name", "pcg"}, {"preconditioner", "multigrid"}, {"cycle", "V"}, {"smooth", 2}},
        json{{"name", "pcg"}, {"preconditioner", "ichol"}},
        json{{"name", "multigrid"}, {"stall_ratio", 0.5}, {"direct_after", 3}},
        json{{"name", "cholmod"},
             {"cycle", "W"},
             {"cycles", 1},
             {"smooth", 5},
             {"preconditioner", "jacobi"},
             {"stall_ratio", 0.2}}})
    EXPECT_EQ(error_of(with(solver)), "") << solver.dump();
  // What the refusal checks, as a list.
  const FlowConfig asked = flow_config_from_json_unchecked(
      with({{"name", "cholmod"}, {"cycles", 7}, {"stall_ratio", 0}}), "cfg.json");
  EXPECT_EQ(inapplicable_keys(asked),
            (std::vector<std::string>{"solver.cycles", "solver.stall_ratio"}));
}

TEST(FlowConfig, ErrorsNameFileAndKey) {
  EXPECT_NE(error_of(json::object()).find("cfg.json: mesh: missing"), std::string::npos);
  EXPECT_NE(error_of(json{{"mesh", "a"}, {"solver", {{"cycels", 2}}}})
                .find("cfg.json: solver.cycels: unknown key"),
            std::string::npos);
  EXPECT_NE(error_of(json{{"mesh", "a"}, {"solver", {{"cycles", "two"}}}})
                .find("solver.cycles: expected an integer"),
            std::string::npos);
  EXPECT_NE(error_of(json{{"mesh", "a"}, {"octree", {{"depth", 42}}}})
                .find("octree.depth: value 42 out of range"),
            std::string::npos);
  EXPECT_NE(error_of(json{{"mesh", "a"}, {"octree", {{"cubature", 4}}}}).find("octree.cubature"),
            std::string::npos);
  EXPECT_NE(error_of(json{{"mesh", "a"}, {"flow", "wilmore"}}).find("flow: unknown value"),
            std::string::npos);
  EXPECT_NE(error_of(json{{"mesh", "a"}, {"dt", -1.0}}).find("dt"), std::string::npos);
  EXPECT_NE(error_of(json{{"mesh", "a"}, {"solver", {{"stall_ratio", 5}}}})
                .find("cfg.json: solver.stall_ratio: value 5 out of range"),
            std::string::npos);
  EXPECT_NE(error_of(json{{"mesh", "a"}, {"solver", {{"fallback_tolerance", 0}}}})
                .find("solver.fallback_tolerance: value 0 out of range"),
            std::string::npos);
  // Every solver with every basis: the hat basis builds a surface hierarchy for multigrid.
  EXPECT_EQ(error_of(json{{"mesh", "a"}, {"solver", {{"name", "multigrid"}}}}), "");
  EXPECT_EQ(
      error_of(json{{"mesh", "a"}, {"solver", {{"name", "pcg"}, {"preconditioner", "multigrid"}}}}),
      "");
  EXPECT_NE(error_of(json{{"mesh", "a"},
                          {"basis", "octree"},
                          {"octree", {{"tracking", "rebuilt"}}},
                          {"flow", "cmcf"}})
                .find("flow"),
            std::string::npos);
  // A multigrid option under a solver without one would be recorded as if it had shaped the run.
  EXPECT_NE(error_of(json{{"mesh", "a"}, {"solver", {{"galerkin_by_term", true}}}})
                .find("cfg.json: solver.galerkin_by_term: applies to a multigrid"),
            std::string::npos);
  EXPECT_EQ(error_of(json{
                {"mesh", "a"},
                {"solver",
                 {{"name", "pcg"}, {"preconditioner", "multigrid"}, {"galerkin_by_term", true}}}}),
            "");
  EXPECT_NE(error_of(json{{"mesh", "a"}, {"solver", {{"precision", "mixed"}}}})
                .find("cfg.json: solver.precision: \"mixed\" applies to a multigrid"),
            std::string::npos);
  EXPECT_NE(
      error_of(json{{"mesh", "a"}, {"solver", {{"name", "multigrid"}, {"precision", "half"}}}})
          .find("solver.precision"),
      std::string::npos);
  // Ranks only where the solve is spread over them; one rank is the default and recorded nowhere.
  EXPECT_NE(error_of(json{{"mesh", "a"}, {"mpi_ranks", 2}})
                .find("cfg.json: mpi_ranks: applies to a solver that runs across MPI ranks"),
            std::string::npos);
  EXPECT_EQ(error_of(json{{"mesh", "a"}, {"mpi_ranks", 1}}), "");
  EXPECT_EQ(error_of(json{{"mesh", "a"}, {"solver", {{"name", "petsc"}}}, {"mpi_ranks", 4}}), "");
  EXPECT_NE(error_of(json{{"mesh", "a"}, {"solver", {{"name", "petsc"}}}, {"mpi_ranks", 0}})
                .find("mpi_ranks"),
            std::string::npos);
  EXPECT_FALSE(
      to_json(flow_config_from_json(json{{"mesh", "a"}}, "cfg.json")).contains("mpi_ranks"));
  EXPECT_EQ(to_json(flow_config_from_json(
                json{{"mesh", "a"}, {"solver", {{"name", "petsc"}}}, {"mpi_ranks", 4}},
                "cfg.json"))["mpi_ranks"],
            4);
  // A lumped mass the octree basis would ignore while the result recorded it.
  EXPECT_NE(error_of(json{{"mesh", "a"}, {"basis", "octree"}, {"mass", "lumped"}})
                .find("cfg.json: mass: \"lumped\" applies to the hat basis only"),
            std::string::npos);
  EXPECT_NO_THROW(
      flow_config_from_json(json{{"mesh", "a"}, {"basis", "hat"}, {"mass", "lumped"}}, "cfg.json"));
}

// Unit-area normalisation rescales the whole surface every step, an open surface's boundary is
// held fixed: refused before the flow starts, naming the key, for any open mesh.
TEST(FlowConfig, NormalizeAreaIsRefusedOnAnOpenSurface) {
  FlowConfig c = flow_config_from_json(
      json{{"mesh", "open_cylinder"}, {"normalize_area", true}, {"steps", 1}}, "cfg.json");
  const MeshSource open = load_mesh_spec("open_cylinder:n_around=16,n_along=8");
  ASSERT_EQ(open.report.boundary_loops, 2);
  try {
    run_flow(c, open);
    ADD_FAILURE() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("normalize_area: the mesh has 2 boundary loop(s)"),
              std::string::npos)
        << e.what();
  }
  c.mesh = "icosphere:level=2";
  EXPECT_EQ(run_flow(c, load_mesh_spec(c.mesh)).result["status"],
            "ok");  // closed: normalised as before
  c.normalize_area = false;
  EXPECT_EQ(run_flow(c, open).result["status"], "ok");
}

// The dense reference's size limit is a configuration error before the first step, not a flow
// that "turned singular" at step 1 (its old result.json said so, with exit status 0).
TEST(FlowConfig, DenseSolverOnALargeSystemIsAConfigError) {
  FlowConfig c = flow_config_from_json(
      json{{"mesh", "icosphere:level=5"}, {"solver", {{"name", "dense"}}}, {"steps", 1}},
      "cfg.json");
  try {
    run_flow(c, load_mesh_spec(c.mesh));
    ADD_FAILURE() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "icosphere:level=5: solver: \"dense\" factorizes at most 5000 functions "
                  "and this basis has 10242 free ones"),
              std::string::npos)
        << e.what();
  }
  c.mesh = "icosphere:level=2";
  EXPECT_EQ(run_flow(c, load_mesh_spec(c.mesh)).result["status"], "ok");
}

// `threads` caps CHOLMOD's BLAS as well as TBB while the flow runs, and the cap is restored
// after (OpenBLAS sizes its own pool to every core otherwise: `--threads 1` ran on all of them).
TEST(FlowConfig, ThreadsCapTheBlasUnderCholmodForTheFlow) {
  const ScopedBlasThreads two(2);  // so that a cap of 1 is told apart from OpenBLAS's own count
  if (blas_threads() < 2) GTEST_SKIP() << "OpenBLAS runs one thread on this machine";
  const int before = blas_threads();
  FlowConfig c = flow_config_from_json(
      json{{"mesh", "icosphere:level=2"}, {"steps", 2}, {"threads", 1}}, "cfg.json");
  std::vector<int> seen;
  FlowObserver observer;
  observer.on_step = [&](int, double, const Positions&) { seen.push_back(blas_threads()); };
  ASSERT_EQ(run_flow(c, load_mesh_spec(c.mesh), observer).result["status"], "ok");
  EXPECT_EQ(seen, std::vector<int>(3, 1));
  EXPECT_EQ(blas_threads(), before);
  {
    const ScopedBlasThreads none(0);  // 0: leave the cap alone
    EXPECT_EQ(blas_threads(), before);
  }
}

TEST(FlowConfig, BlasThreadsAutoFollowsTheSizeAndAGivenCountIsCappedAtThreads) {
  // The rule: one thread for a small system, up to four for a large one, never more than TBB's.
  EXPECT_EQ(auto_blas_threads(16, kBlasThreadsFromDimension - 1), 1);
  EXPECT_EQ(auto_blas_threads(16, kBlasThreadsFromDimension), kMaxAutoBlasThreads);
  EXPECT_EQ(auto_blas_threads(2, 1000000), 2);
  EXPECT_EQ(auto_blas_threads(0, 1000000), 1);
  const ScopedBlasThreads two(2);
  if (blas_threads() < 2 || runnable_threads(2) < 2)
    GTEST_SKIP() << "one thread runs on this machine";
  // What CHOLMOD ran with, as OpenBLAS reported it inside the factorization (its settings).
  auto ran = [](const json& j) {
    const FlowConfig c = flow_config_from_json(j, "cfg.json");
    const FlowOutcome o = run_flow(c, load_mesh_spec(c.mesh));
    return std::stoi(o.result.at("solver_settings").at("blas_threads").get<std::string>());
  };
  // 642 unknowns: auto gives one thread, however many may run.
  EXPECT_EQ(ran(json{{"mesh", "icosphere:level=3"}, {"steps", 1}, {"threads", 2}}), 1);
  EXPECT_EQ(
      ran(json{{"mesh", "icosphere:level=3"}, {"steps", 1}, {"threads", 2}, {"blas_threads", 2}}),
      2);
  EXPECT_EQ(
      ran(json{{"mesh", "icosphere:level=3"}, {"steps", 1}, {"threads", 1}, {"blas_threads", 2}}),
      1);
  // 40962 unknowns: both threads.
  EXPECT_EQ(ran(json{{"mesh", "icosphere:level=6"}, {"steps", 1}, {"threads", 2}}), 2);
  EXPECT_NE(error_of(json{{"mesh", "a"}, {"blas_threads", -1}}).find("blas_threads"),
            std::string::npos);
  // Only CHOLMOD reads it: a count for another solver is refused, not recorded as if it counted.
  EXPECT_NE(error_of(json{{"mesh", "a"}, {"blas_threads", 2}, {"solver", {{"name", "multigrid"}}}})
                .find("blas_threads"),
            std::string::npos);
}

}  // namespace
}  // namespace mcf
