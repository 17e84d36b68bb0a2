// The hat basis with the multigrid solver: the Galerkin coarse operators of its surface hierarchy
// against P^T A P formed directly, cycles converging to CHOLMOD's solution, the same bits for one
// and two threads, and flows with multigrid and multigrid-preconditioned CG against CHOLMOD's.

#include "../residual_floor.h"
#include "flow_test_util.h"

#include "bases/hat_basis.h"
#include "solvers/cholmod_solver.h"
#include "solvers/multigrid.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <algorithm>

namespace mcf {
namespace {

using nlohmann::json;
using testing::falls_above_rounding_floor;

struct HatSystem {
  TriangleMesh mesh;
  std::unique_ptr<HatBasis> basis;
  SparseMatrix A;
  Eigen::MatrixXd B;
};

/// M + dt K of a mesh's hat basis with its hierarchy, and the right-hand sides M X.
HatSystem hat_system(const std::string& spec, double dt, int coarsest = 300) {
  HatSystem s;
  s.mesh = load_mesh_spec(spec).mesh;
  s.basis = std::make_unique<HatBasis>(s.mesh, MassKind::consistent,
                                       SurfaceHierarchyOptions{coarsest, 16});
  const SparseMatrix M = s.basis->mass(), K = s.basis->stiffness();
  s.A = M + dt * K;
  s.A.makeCompressed();
  s.B = M * s.basis->initial_coefficients();
  return s;
}

HierarchyView view(const HatBasis& b) {
  return HierarchyView{b.prolongations(), b.colours()};
}

/// The RMS distance between two flows' final vertices, relative to the second's bounding-box
/// diagonal.
double relative_rms(const FlowOutcome& o, const FlowOutcome& exact) {
  const Positions& V = exact.final_mesh.vertices;
  const double size = (V.colwise().maxCoeff() - V.colwise().minCoeff()).norm();
  return std::sqrt((o.final_mesh.vertices - V).rowwise().squaredNorm().mean()) / size;
}

TEST(HatMultigrid, GalerkinOperatorsArePTAPFormedDirectly) {
  const HatSystem s = hat_system("cgal:armadillo", 1e-3);
  MultigridSolver mg;
  ASSERT_TRUE(mg.set_matrix(s.A, view(*s.basis)).ok());
  const auto& P = *s.basis->prolongations();
  ASSERT_EQ(mg.levels(), int(P.size()) + 1);
  ASSERT_GE(mg.levels(), 4);
  SparseMatrix Af = s.A;
  for (int l = int(P.size()) - 1; l >= 0; --l) {
    const SparseMatrix& Pl = P[std::size_t(l)];
    const SparseMatrix direct = SparseMatrix(Pl.transpose()) * (Af * Pl);
    const SparseMatrix ours = mg.level_matrix(l);
    ASSERT_EQ(ours.rows(), direct.rows());
    EXPECT_LT(SparseMatrix(ours - direct).norm() / direct.norm(), 1e-13) << "level " << l;
    Af = ours;
  }
  // The finest level (a planar graph) is relaxed colour by colour.
  EXPECT_TRUE(mg.level_is_coloured(mg.levels() - 1));
}

TEST(HatMultigrid, CyclesConvergeToTheCholmodSolution) {
  for (double dt : {1e-5, 1e-3}) {
    const HatSystem s = hat_system("cgal:armadillo", dt);
    CholmodSolver direct;
    ASSERT_TRUE(direct.set_matrix(s.A).ok());
    Eigen::MatrixXd exact(s.B.rows(), 3);
    ASSERT_TRUE(direct.solve(s.B, exact).ok());
    for (MultigridCycle cycle : {MultigridCycle::V, MultigridCycle::W}) {
      MultigridOptions o;
      o.cycle = cycle;
      o.cycles = 200;
      o.tolerance = 1e-13;
      o.pre_smooth = o.post_smooth = cycle == MultigridCycle::V ? 2 : 5;
      MultigridSolver mg(o);
      ASSERT_TRUE(mg.set_matrix(s.A, view(*s.basis)).ok());
      Eigen::MatrixXd x;
      const SolveReport r = mg.solve(s.B, x);
      EXPECT_EQ(r.status, SolveStatus::converged) << dt;
      EXPECT_LT((x - exact).norm() / exact.norm(), 1e-10) << "dt " << dt << " " << to_string(cycle);
      // Each cycle reduces the residual (above the rounding floor): the smoother and the coarse
      // correction work together.
      EXPECT_TRUE(falls_above_rounding_floor(r.residuals))
          << "dt " << dt << " " << to_string(cycle);
    }
  }
}

TEST(HatMultigrid, OneAndTwoThreadsGiveTheSameBits) {
  const HatSystem s = hat_system("sphere:vertices=60000", 1e-3);
  auto solve = [&](int threads) {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, threads);
    MultigridOptions o;
    o.cycles = 3;
    MultigridSolver mg(o);
    EXPECT_TRUE(mg.set_matrix(s.A, view(*s.basis)).ok());
    // Blocks of one parity are relaxed in parallel only where the finest level has several.
    const std::vector<int> blocks = mg.relaxation_blocks(mg.levels() - 1);
    EXPECT_GE(*std::max_element(blocks.begin(), blocks.end()), 3);
    Eigen::MatrixXd x;
    mg.solve(s.B, x);
    return x;
  };
  const Eigen::MatrixXd one = solve(1), two = solve(2);
  EXPECT_EQ((one - two).cwiseAbs().maxCoeff(), 0.0);
}

TEST(HatMultigrid, FlowsWithMultigridFollowCholmod) {
  for (const char* flow : {"cmcf", "heat"}) {
    const json base = {
        {"mesh", "cgal:armadillo"}, {"basis", "hat"}, {"flow", flow}, {"dt", 1e-3}, {"steps", 5}};
    json cholmod = base, cycles = base, pcg = base;
    cholmod["solver"] = {{"name", "cholmod"}};
    cycles["solver"] = {{"name", "multigrid"}, {"cycles", 4}};
    pcg["solver"] = {{"name", "pcg"}, {"preconditioner", "multigrid"}, {"tolerance", 1e-10}};
    const FlowOutcome exact = testing::run(cholmod);
    const double size = (exact.final_mesh.vertices.colwise().maxCoeff() -
                         exact.final_mesh.vertices.colwise().minCoeff())
                            .norm();
    for (const json* j : {&cycles, &pcg}) {
      const FlowOutcome o = testing::run(*j);
      ASSERT_EQ(o.result["status"], "ok") << flow << " " << (*j)["solver"];
      EXPECT_GT(o.result["system"]["levels"].get<int>(), 2);
      EXPECT_GT(o.result["system"]["setup_seconds"]["hierarchy"].get<double>(), 0.0);
      const double rms = std::sqrt(
          (o.final_mesh.vertices - exact.final_mesh.vertices).rowwise().squaredNorm().mean());
      EXPECT_LT(rms / size, 1e-7) << flow << " " << (*j)["solver"];
      EXPECT_EQ(o.result["steps"].back()["solver"]["status"], "converged")
          << flow << " " << (*j)["solver"];
    }
  }
}

// The multigrid's fallback ends in a factorization (solvers/multigrid_fallback.h): with a stall
// bound no V-cycle meets (0.01) every step falls back, CG by the cycle gets one iteration
// (solver.direct_after 1), which cannot reach the bound's target, and CHOLMOD solves the step;
// later steps go to it straight after their cycles. Every step is then an exact solve, so the
// flow is CHOLMOD's flow up to rounding. With direct_after 0 CG alone finishes the steps. MCF on
// the dino at δ = 1e-3, the degenerating case of the work_precision study, for 3 steps.
TEST(HatMultigrid, StalledStepsEndInTheFactorizationAndFlowAsCholmod) {
  const json base = {
      {"mesh", "cgal:dino"}, {"basis", "hat"}, {"flow", "mcf"}, {"dt", 1e-3}, {"steps", 3}};
  json cholmod = base, direct = base, cg = base;
  cholmod["solver"] = {{"name", "cholmod"}};
  direct["solver"] = {{"name", "multigrid"}, {"cycle", "V"},        {"cycles", 2},
                      {"smooth", 2},         {"stall_ratio", 0.01}, {"direct_after", 1}};
  cg["solver"] = direct["solver"];
  cg["solver"]["direct_after"] = 0;
  const FlowOutcome exact = testing::run(cholmod), d = testing::run(direct), c = testing::run(cg);
  ASSERT_EQ(exact.result["status"], "ok");
  ASSERT_EQ(d.result["status"], "ok");
  ASSERT_EQ(c.result["status"], "ok");
  int step = 0;
  for (const auto& s : d.result["steps"]) {
    ++step;
    const auto& solver = s["solver"];
    ASSERT_TRUE(solver.contains("fallback")) << "step " << step;
    EXPECT_EQ(solver["fallback"]["direct_solves"], 1) << "step " << step;
    EXPECT_EQ(solver["fallback"]["iterations"], step == 1 ? 1 : 0) << "step " << step;
    EXPECT_LT(solver["relative_residual"].get<double>(), 1e-10) << "step " << step;
    EXPECT_EQ(solver["status"], "converged");
  }
  for (const auto& s : c.result["steps"]) {
    ASSERT_TRUE(s["solver"].contains("fallback"));
    EXPECT_EQ(s["solver"]["fallback"]["direct_solves"], 0);
    EXPECT_GT(s["solver"]["fallback"]["iterations"].get<int>(), 1);
  }
  const auto rms = [&](const FlowOutcome& o) { return relative_rms(o, exact); };
  // The two exact flows differ by rounding (the multigrid's finest matrix sums a M + b K in its own
  // order), which the thinning limbs amplify (measured: 2.5e-9 of the box's diagonal); CG stopped
  // at its target leaves the flow 1e-5 away.
  EXPECT_LT(rms(d), 1e-7);
  EXPECT_GT(rms(c), 1e-7);
}

// The residual guard (solvers/multigrid_fallback.h) near a fold: MCF at δ = 1e-3 on the catalogue's
// dino, whose limbs thin until the fourth step. Plain fixed-work cycles (the default one W(5,5) and
// the fast two V(2,2)) end every step above the default bound 1e-4 (measured: 5.7e-4 to 2.9e-3) and
// say max_iterations, never converged. Guarded, every step ends at or below the bound, says
// converged, and records what it added (extra cycles, CG, the factorization); the flow then ends
// far closer to the CHOLMOD flow than the plain cycles' (measured: 1e-2 of their distance).
TEST(HatMultigrid, GuardedStepsNearAFoldEndUnderTheBoundAndSaySo) {
  const json base = {
      {"mesh", "cgal:dino"}, {"basis", "hat"}, {"flow", "mcf"}, {"dt", 1e-3}, {"steps", 4}};
  json cholmod = base;
  cholmod["solver"] = {{"name", "cholmod"}};
  const FlowOutcome exact = testing::run(cholmod);
  ASSERT_EQ(exact.result["status"], "ok");
  const auto rms = [&](const FlowOutcome& o) { return relative_rms(o, exact); };
  for (const json& cycles :
       {json{{"name", "multigrid"}},
        json{{"name", "multigrid"}, {"cycle", "V"}, {"smooth", 2}, {"cycles", 2}}}) {
    json plain = base, guarded = base;
    plain["solver"] = guarded["solver"] = cycles;
    plain["solver"]["stall_ratio"] = 0;
    plain["solver"]["residual_bound"] = 0;
    const FlowOutcome p = testing::run(plain), g = testing::run(guarded);
    ASSERT_EQ(p.result["status"], "ok") << cycles;
    ASSERT_EQ(g.result["status"], "ok") << cycles;
    EXPECT_EQ(g.result["config"]["solver"]["residual_bound"], 1e-4);
    int above = 0, extra_cycles = 0, direct = 0;
    for (const auto& s : p.result["steps"]) {
      EXPECT_EQ(s["solver"]["status"], "max_iterations") << cycles;
      above += s["solver"]["relative_residual"].get<double>() > 1e-4 ? 1 : 0;
    }
    EXPECT_EQ(above, 4) << cycles;  // the case tests the guard only if the cycles miss the bound
    for (const auto& s : g.result["steps"]) {
      const auto& solver = s["solver"];
      EXPECT_EQ(solver["status"], "converged") << cycles << " step " << s["step"];
      EXPECT_LE(solver["relative_residual"].get<double>(), 1e-4) << cycles << " step " << s["step"];
      ASSERT_TRUE(solver.contains("fallback")) << cycles << " step " << s["step"];
      extra_cycles += solver["fallback"]["extra_cycles"].get<int>();
      direct += solver["fallback"]["direct_solves"].get<int>();
      const std::string why = solver["message"];
      EXPECT_TRUE(why.find("above the residual bound") != std::string::npos ||
                  why.find("stalled") != std::string::npos)
          << why;
    }
    EXPECT_GT(extra_cycles, 0) << cycles;
    EXPECT_GT(direct, 0) << cycles;  // the fold's steps need the factorization
    EXPECT_LT(rms(g), 0.1 * rms(p)) << cycles;
  }
}

// Away from folds (cMCF on a scan, once the first steps have smoothed its noise) the start fits
// the integrator's prediction: the default keeps such a step's cycles above the bound and says
// so, solver.bound_smooth_steps holds it to the bound; both flows stay close to CHOLMOD's.
TEST(HatMultigrid, SmoothStepsKeepTheirCyclesAndSaySo) {
  const json base = {{"mesh", "cgal:bunny00"},           {"basis", "hat"}, {"flow", "cmcf"},
                     {"normalize_area", true},           {"dt", 1e-3},     {"steps", 4},
                     {"solver", {{"name", "multigrid"}}}};
  json cholmod = base, strict = base;
  cholmod["solver"] = {{"name", "cholmod"}};
  strict["solver"]["bound_smooth_steps"] = true;
  const FlowOutcome exact = testing::run(cholmod), kept = testing::run(base),
                    held = testing::run(strict);
  ASSERT_EQ(kept.result["status"], "ok");
  ASSERT_EQ(held.result["status"], "ok");
  EXPECT_EQ(kept.result["config"]["solver"]["bound_smooth_steps"], false);
  int smooth = 0;
  for (const auto& s : kept.result["steps"]) {
    const auto& solver = s["solver"];
    const double r = solver["relative_residual"];
    const std::string why = solver["message"];
    if (why.find("kept: a smooth step") != std::string::npos) {
      ++smooth;
      EXPECT_EQ(solver["status"], "max_iterations") << s["step"];
      EXPECT_GT(r, 1e-4) << s["step"];
      EXPECT_GT(s["step"].get<int>(), 1);  // the first step has no prediction
    } else {
      EXPECT_EQ(solver["status"], "converged") << s["step"] << why;
      EXPECT_LE(r, 1e-4) << s["step"];
    }
  }
  EXPECT_GE(smooth, 1);  // the case tests the rule only if a smooth step ends above the bound
  for (const auto& s : held.result["steps"]) {
    EXPECT_EQ(s["solver"]["status"], "converged") << s["step"];
    EXPECT_LE(s["solver"]["relative_residual"].get<double>(), 1e-4) << s["step"];
  }
  // The kept steps leave the flow about 2e-5 of the bounding box's diagonal from CHOLMOD's (every
  // step held: 2e-6); the flow's own error against the once-refined mesh, which
  // benchmarks/configs/residual_guard.json measures, is larger.
  EXPECT_LT(relative_rms(kept, exact), 1e-4);
  EXPECT_LT(relative_rms(held, exact), relative_rms(kept, exact));
}

// solver.galerkin_by_term (solvers/multigrid.h): the coarse operators differ from the sum's
// Galerkin products by rounding only, so the flow's final mesh stays within 1e-10 of the bounding
// box's diagonal of the flow without it (a few cycles per step: the rounding moves the iterate by
// about the contraction times that; cMCF changes only the mass, heat flow nothing). MCF at
// δ = 1e-5: at 1e-3 the armadillo's MCF pinches within a few steps, where the slightest change
// of the iterate changes the flow.
TEST(HatMultigrid, GalerkinByTermFlowsAsTheSumsGalerkinProduct) {
  for (const char* flow : {"cmcf", "heat", "mcf"}) {
    const json base = {{"mesh", "cgal:armadillo"},
                       {"basis", "hat"},
                       {"flow", flow},
                       {"dt", std::string(flow) == "mcf" ? 1e-5 : 1e-3},
                       {"steps", 4},
                       {"solver", {{"name", "multigrid"}, {"cycles", 3}}}};
    json by_term = base;
    by_term["solver"]["galerkin_by_term"] = true;
    const FlowOutcome plain = testing::run(base), o = testing::run(by_term);
    ASSERT_EQ(o.result["status"], "ok") << flow;
    EXPECT_EQ(o.result["config"]["solver"]["galerkin_by_term"], true);
    EXPECT_FALSE(plain.result["config"]["solver"].contains("galerkin_by_term"));
    const double size = (plain.final_mesh.vertices.colwise().maxCoeff() -
                         plain.final_mesh.vertices.colwise().minCoeff())
                            .norm();
    const double worst =
        (o.final_mesh.vertices - plain.final_mesh.vertices).rowwise().norm().maxCoeff();
    EXPECT_LE(worst, 1e-10 * size) << flow;
  }
}

// solver.precision "mixed" (MultigridOptions::mixed_precision): the finest sweeps read single
// precision, 6 bytes an entry instead of 10, inside a double-precision residual correction. On a
// sphere the contraction per V(2,2)-cycle stays within 10% of double precision's, and the cycles
// still reach a relative residual of 1e-11, which rounded finest sweeps without the correction
// could not (they stall near 1e-8: solvers/smoother.h).
TEST(HatMultigrid, MixedPrecisionContractsAsDoubleAndReachesTheSolution) {
  const HatSystem s = hat_system("sphere:vertices=20000", 1e-3);
  auto run = [&](bool mixed, double tolerance, int cycles) {
    MultigridOptions o;
    o.cycle = MultigridCycle::V;
    o.pre_smooth = o.post_smooth = 2;
    o.cycles = cycles;
    o.tolerance = tolerance;
    o.measure_contraction = true;
    o.mixed_precision = mixed;
    MultigridSolver mg(o);
    EXPECT_TRUE(mg.set_matrix(s.A, view(*s.basis)).ok());
    const int top = mg.levels() - 1;
    EXPECT_TRUE(mg.level_has_compact_smoother(top));
    EXPECT_EQ(mg.level_sweep_entry_bytes(top), mixed ? 6 : 10);
    Eigen::MatrixXd x = Eigen::MatrixXd::Zero(s.A.rows(), 3);
    const SolveReport r = mg.solve(s.B, x);
    return std::make_pair(r, x);
  };
  const auto [plain, xp] = run(false, 0, 5);
  const auto [mixed, xm] = run(true, 0, 5);
  ASSERT_GT(plain.contraction, 0);
  EXPECT_LE(mixed.contraction, 1.1 * plain.contraction);
  EXPECT_GE(mixed.contraction, plain.contraction / 1.1);
  const auto [tight, xt] = run(true, 1e-11, 200);
  EXPECT_EQ(tight.status, SolveStatus::converged);
  EXPECT_LT(tight.relative_residual, 1e-11);
  CholmodSolver exact;
  ASSERT_TRUE(exact.set_matrix(s.A).ok());
  Eigen::MatrixXd xc;
  ASSERT_TRUE(exact.solve(s.B, xc).ok());
  EXPECT_LT((xt - xc).norm(), 1e-9 * xc.norm());
}

// The flow with mixed precision against the flow in double precision, both solving each step to
// a relative residual of 1e-10: each step's two solutions then differ by at most about κ(A) 2e-10
// relative, which over 5 steps is far below the 1e-7 of the bounding box's diagonal tested here,
// the bound that any two multigrid solves to 1e-10 meet (FlowsWithMultigridFollowCholmod). MCF at
// δ = 1e-5, as above.
TEST(HatMultigrid, MixedPrecisionFlowsAsDoublePrecision) {
  for (const char* flow : {"cmcf", "mcf"}) {
    const json base = {{"mesh", "cgal:armadillo"},
                       {"basis", "hat"},
                       {"flow", flow},
                       {"dt", std::string(flow) == "mcf" ? 1e-5 : 1e-3},
                       {"steps", 5},
                       {"solver",
                        {{"name", "multigrid"},
                         {"cycle", "V"},
                         {"smooth", 2},
                         {"cycles", 100},
                         {"tolerance", 1e-10}}}};
    json mixed = base;
    mixed["solver"]["precision"] = "mixed";
    const FlowOutcome plain = testing::run(base), o = testing::run(mixed);
    ASSERT_EQ(o.result["status"], "ok") << flow;
    EXPECT_EQ(o.result["config"]["solver"]["precision"], "mixed");
    EXPECT_EQ(o.result["steps"].back()["solver"]["status"], "converged") << flow;
    const double size = (plain.final_mesh.vertices.colwise().maxCoeff() -
                         plain.final_mesh.vertices.colwise().minCoeff())
                            .norm();
    const double rms = std::sqrt(
        (o.final_mesh.vertices - plain.final_mesh.vertices).rowwise().squaredNorm().mean());
    EXPECT_LT(rms / size, 1e-7) << flow;
  }
}

}  // namespace
}  // namespace mcf
