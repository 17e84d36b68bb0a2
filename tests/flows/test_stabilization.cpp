// The normal-gradient stabilization of the octree flows' increments (docs/octree-multigrid.md,
// "Stabilization"): plain W-cycles converge on the stabilized system as multigrid should, to the
// direct solution of the same system; the term acts on increments only, so it never moves a
// surface the flow would not move, and what it changes of a step stays within the octree's own
// discretization error (the analytic sphere, the cotangent flow of a real model).

#include "flow_test_util.h"

#include "datasets/bvh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace mcf {
namespace {

using nlohmann::json;
using testing::run;

/// The cycles run as given: these tests measure them, so the multigrid's guard that takes over
/// from stalled cycles or from cycles that end above the residual bound is off. The weight is the
/// cycles' 0.5 whatever the solver (a direct solver's own default is the definite-only 1e-6, tested
/// apart below).
json octree_flow(const std::string& mesh, int depth, const std::string& stabilization,
                 const json& solver) {
  json s = solver;
  if (s.value("name", "") == "multigrid") {
    s["stall_ratio"] = 0;
    s["residual_bound"] = 0;
  }
  return json{{"mesh", mesh},
              {"basis", "octree"},
              {"octree",
               {{"depth", depth}, {"stabilization", stabilization}, {"stabilization_weight", 0.5}}},
              {"solver", s},
              {"dt", 1e-3},
              {"steps", 1}};
}

/// RMS distance of a's vertices to the surface b.
double vertex_distance(const TriangleMesh& a, const TriangleMesh& b) {
  const TriangleBvh tree(b.vertices, b.faces);
  double sum = 0.0;
  for (Eigen::Index v = 0; v < a.vertices.rows(); ++v)
    sum += tree.closest(a.vertices.row(v).transpose()).squared_distance;
  return std::sqrt(sum / double(a.vertices.rows()));
}

std::vector<double> residuals(const FlowOutcome& o) {
  return o.result["steps"].back()["solver"]["residuals"].get<std::vector<double>>();
}

// At depths 5 and 6, W(5,5) cycles reach the CHOLMOD solution of the same stabilized system to
// 1e-10 in at most 15 cycles, on the sphere and on a real model; the paper's system, solved by
// the same cycles, does not get there within 60.
TEST(Stabilization, WCyclesReachTheDirectSolutionWithinFifteenCycles) {
  for (const char* mesh : {"icosphere:level=5", "cgal:bunny00"}) {
    for (int depth : {5, 6}) {
      SCOPED_TRACE(std::string(mesh) + " depth " + std::to_string(depth));
      const json mg_solver = {{"name", "multigrid"}, {"cycles", 15}, {"tolerance", 1e-10}};
      const FlowOutcome exact =
          run(octree_flow(mesh, depth, "normal-gradient", {{"name", "cholmod"}}));
      const FlowOutcome mg = run(octree_flow(mesh, depth, "normal-gradient", mg_solver));
      EXPECT_EQ(mg.result["steps"][0]["solver"]["status"], "converged");
      EXPECT_LE(residuals(mg).size(), 15u);
      const Positions &a = mg.final_mesh.vertices, &b = exact.final_mesh.vertices;
      const Positions& v0 = load_mesh_spec(mesh).mesh.vertices;
      // The step's vertex motion, solved to 1e-10 of itself.
      EXPECT_LT((a - b).norm(), 1e-8 * (b - v0).norm());
      json plain_solver = mg_solver;
      plain_solver["cycles"] = 60;
      const FlowOutcome plain = run(octree_flow(mesh, depth, "none", plain_solver));
      EXPECT_EQ(residuals(plain).size(), 60u) << "the paper's system converged as fast";
    }
  }
}

// Every cycle on the stabilized system cuts the residual by 10x or more (down to 1e-11), while
// the paper's system stalls (late cycles above 0.5), warm-started as in a flow (step 3).
TEST(Stabilization, EveryWCycleGainsTenfold) {
  for (const char* stabilization : {"normal-gradient", "none"}) {
    json j =
        octree_flow("icosphere:level=5", 6, stabilization, {{"name", "multigrid"}, {"cycles", 8}});
    j["steps"] = 3;
    const std::vector<double> r = residuals(run(j));
    ASSERT_EQ(r.size(), 8u);
    double worst = 0.0;
    for (std::size_t i = 1; i < r.size(); ++i)
      if (r[i - 1] > 1e-11) worst = std::max(worst, r[i] / r[i - 1]);
    if (std::string(stabilization) == "none")
      EXPECT_GT(worst, 0.5);
    else
      EXPECT_LT(worst, 0.1);
  }
}

// A time step that moves nothing moves nothing: the term is applied to the increment, never to
// the position (the identity's extension has n·∇x = n, which a stabilized position solve would
// pull on by O(ρ)).
TEST(Stabilization, ATinyStepLeavesTheSurfaceInPlace) {
  for (const char* mesh : {"icosphere:level=4", "cgal:bunny00"}) {
    json j = octree_flow(mesh, 6, "normal-gradient", {{"name", "cholmod"}});
    j["dt"] = 1e-12;
    const FlowOutcome o = run(j);
    const Positions& v0 = load_mesh_spec(mesh).mesh.vertices;
    EXPECT_LT((o.final_mesh.vertices - v0).cwiseAbs().maxCoeff(), 1e-9) << mesh;
    EXPECT_GT(o.result["steps"][0]["solver"]["stabilization_rho"].get<double>(), 0.0);
  }
}

// What the term changes stays within the discretization's own error: on the sphere the
// stabilized flow is closer to the semi-implicit radius than the paper's system; on a real model
// the term acts on the increment's change only, so the flow's distance to the cotangent flow
// approaches the paper's as the increments settle: its excess is larger after 3 steps than after
// 20 (vertex-to-surface RMS, depth 6, δ = 1e-5).
TEST(Stabilization, TheFlowStaysWithinTheDiscretizationError) {
  const auto radial = [](const FlowOutcome& o) {
    return o.result["steps"][0]["radial_error"]["rms"].get<double>();
  };
  const FlowOutcome plain = run(octree_flow("icosphere:level=4", 6, "none", {{"name", "cholmod"}}));
  const FlowOutcome stab =
      run(octree_flow("icosphere:level=4", 6, "normal-gradient", {{"name", "cholmod"}}));
  EXPECT_LT(radial(stab), radial(plain));

  double ratio[2];
  int k = 0;
  for (int steps : {3, 20}) {
    json hat = {{"mesh", "cgal:bunny00"}, {"basis", "hat"}, {"dt", 1e-5}, {"steps", steps}};
    const TriangleMesh reference = run(hat).final_mesh;
    double distance[2];
    int s = 0;
    for (const char* stabilization : {"none", "normal-gradient"}) {
      json j = octree_flow("cgal:bunny00", 6, stabilization, {{"name", "cholmod"}});
      j["dt"] = 1e-5;
      j["steps"] = steps;
      distance[s++] = vertex_distance(run(j).final_mesh, reference);
    }
    ratio[k++] = distance[1] / distance[0];
  }
  EXPECT_LT(ratio[1], ratio[0]);
  EXPECT_LT(ratio[1], 2.5);  // measured 1.97 (2.8 after 3 steps; 6.3 without the prediction)
}

// A direct solver's default weight only makes the system definite: its flow lands on the paper's
// surface (docs/octree-multigrid.md, "Stabilization"), at least 100x closer to it than the
// cycles' weight of 0.5 leaves the flow, and result.json records the weight that ran.
TEST(Stabilization, ADirectSolverTakesTheTermOnlyToBeDefinite) {
  const auto flow = [](const json& octree) {
    json j = {{"mesh", "cgal:bunny00"},          {"basis", "octree"}, {"octree", octree},
              {"solver", {{"name", "cholmod"}}}, {"dt", 1e-3},        {"steps", 3}};
    j["octree"]["depth"] = 6;
    return run(j);
  };
  const FlowOutcome paper = flow({{"stabilization", "none"}});
  const FlowOutcome definite = flow({{"stabilization", "normal-gradient"}});
  const FlowOutcome cycles =
      flow({{"stabilization", "normal-gradient"}, {"stabilization_weight", 0.5}});
  EXPECT_EQ(definite.result["config"]["octree"]["stabilization_weight"], 1e-6);
  ASSERT_EQ(definite.result["status"], "ok");
  const double near = (definite.final_mesh.vertices - paper.final_mesh.vertices).norm();
  const double far = (cycles.final_mesh.vertices - paper.final_mesh.vertices).norm();
  EXPECT_GT(far, 0.0);
  EXPECT_LT(near, 0.01 * far) << near << " against " << far;
}

}  // namespace
}  // namespace mcf
