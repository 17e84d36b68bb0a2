// Flows on the sphere against analytic radii (docs/design.md "Conventions"), and against each
// other.

#include "flow_test_util.h"

#include "config/config_reader.h"
#include "datasets/validate.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>
#include <tuple>

namespace mcf {
namespace {

using nlohmann::json;
using testing::last;
using testing::mean_radius;
using testing::run;

TEST(SphereFlows, SemiImplicitRadiusConvergesUnderRefinement) {
  // r_{n+1} = r_n³/(r_n² + 2δ) is what the semi-implicit step gives on the exact sphere; on a
  // mesh the error is spatial, O(h²): about 4x smaller each time the edge length halves.
  std::vector<double> errors;
  for (int level = 2; level <= 5; ++level) {
    const auto o = run(
        json{{"mesh", "icosphere:level=" + std::to_string(level)}, {"dt", 1e-3}, {"steps", 10}});
    ASSERT_EQ(o.result["status"], "ok");
    errors.push_back(last(o, "radial_error", "rms"));
  }
  for (std::size_t i = 1; i < errors.size(); ++i) {
    const double ratio = errors[i - 1] / errors[i];
    EXPECT_GT(ratio, 3.0) << "level " << i + 2;
    EXPECT_LT(ratio, 5.5) << "level " << i + 2;
  }
}

TEST(SphereFlows, SphereOfRadiusTwoFollowsTheContinuousRadii) {
  // r0 = 2 (so a formula that drops r0 fails): MCF r(t) = sqrt(r0² - 4t), heat flow
  // r0 exp(-2t/r0²) (docs/design.md "Conventions"). At t = 0.5 they are 1.414 and 1.558.
  const double r0 = 2, dt = 2e-3, T = 0.5;
  const int steps = int(std::lround(T / dt));
  for (const char* flow : {"mcf", "heat"}) {
    const bool heat = std::string(flow) == "heat";
    const auto o = run(
        json{{"mesh", "icosphere:level=4,radius=2"}, {"flow", flow}, {"dt", dt}, {"steps", steps}});
    ASSERT_EQ(o.result["status"], "ok") << flow;
    const json& e = o.result["steps"].back()["radial_error"];
    double discrete = r0;
    for (int n = 0; n < steps; ++n)
      discrete = heat ? discrete / (1 + 2 * dt / (r0 * r0))
                      : std::pow(discrete, 3) / (discrete * discrete + 2 * dt);
    const double continuous = heat ? r0 * std::exp(-2 * T / (r0 * r0)) : std::sqrt(r0 * r0 - 4 * T);
    EXPECT_NEAR(e["radius_semi_implicit"].get<double>(), discrete, 1e-12) << flow;
    EXPECT_NEAR(e["radius_continuous"].get<double>(), continuous, 1e-12) << flow;
    // The mesh follows the continuous radius (measured: rms 4.6e-4 for MCF, 3.9e-4 for heat;
    // the two flows' radii are 0.14 apart, so a mix-up of the flows fails).
    EXPECT_LT(e["rms_continuous"].get<double>(), 1e-3) << flow;
    EXPECT_NEAR(e["mean_radius"].get<double>(), continuous, 1e-3) << flow;
    EXPECT_LT(e["max_continuous"].get<double>(), 2e-3) << flow;
  }
}

TEST(SphereFlows, SolversAgree) {
  // CHOLMOD, PCG (two preconditioners) and a dense LLT solve give the same flow.
  const json base = {{"mesh", "icosphere:level=3"}, {"dt", 1e-3}, {"steps", 5}};
  json dense = base, cholmod = base, ichol = base, jacobi = base;
  dense["solver"] = {{"name", "dense"}};
  cholmod["solver"] = {{"name", "cholmod"}};
  ichol["solver"] = {{"name", "pcg"}, {"preconditioner", "ichol"}, {"tolerance", 1e-13}};
  jacobi["solver"] = {{"name", "pcg"}, {"preconditioner", "jacobi"}, {"tolerance", 1e-13}};
  const Positions reference = run(dense).final_mesh.vertices;
  for (const json& j : {cholmod, ichol, jacobi}) {
    const Positions V = run(j).final_mesh.vertices;
    EXPECT_LT((V - reference).norm() / reference.norm(), 1e-10) << j["solver"].dump();
  }
}

TEST(SphereFlows, CmcfEqualsMcfOnTheSphere) {
  // On a sphere K_0 x = λ M_0 x and M_t = (r/r0)² M_0, so keeping K_0 changes nothing
  // (up to the mesh's deviation from a perfect sphere).
  const json base = {{"mesh", "icosphere:level=4"}, {"dt", 1e-3}, {"steps", 20}};
  json cmcf = base;
  cmcf["flow"] = "cmcf";
  const auto a = run(base), b = run(cmcf);
  const Positions& Va = a.final_mesh.vertices;
  const Positions& Vb = b.final_mesh.vertices;
  EXPECT_LT((Va - Vb).cwiseAbs().maxCoeff(), 1e-4);
  EXPECT_NEAR(last(b, "radial_error", "rms"), last(a, "radial_error", "rms"), 1e-4);
  // And the first step is identical: K_0 is the current K then.
  json one = base, one_c = cmcf;
  one["steps"] = 1;
  one_c["steps"] = 1;
  EXPECT_LT((run(one).final_mesh.vertices - run(one_c).final_mesh.vertices).norm(), 1e-13);
}

TEST(SphereFlows, HeatFlowMatchesItsClosedForm) {
  // Heat flow keeps M_0, K_0: r_n = r0 (1 + 2δ/r0²)^-n, and r0 exp(-2t/r0²) as δ → 0.
  std::vector<double> errors;
  for (int level = 3; level <= 5; ++level) {
    const auto o = run(json{{"mesh", "icosphere:level=" + std::to_string(level)},
                            {"flow", "heat"},
                            {"dt", 1e-2},
                            {"steps", 20}});
    errors.push_back(last(o, "radial_error", "rms"));
    EXPECT_NEAR(o.result["steps"].back()["radial_error"]["radius_semi_implicit"].get<double>(),
                std::pow(1.02, -20), 1e-14);
  }
  EXPECT_GT(errors[0] / errors[1], 3.0);
  EXPECT_GT(errors[1] / errors[2], 3.0);
  EXPECT_LT(errors[2], 2e-4);
  // Heat flow keeps the shape a sphere for any step: the mean radius follows the recursion.
  const auto big =
      run(json{{"mesh", "icosphere:level=4"}, {"flow", "heat"}, {"dt", 0.1}, {"steps", 5}});
  EXPECT_LT(last(big, "radial_error", "rms"), 1e-2 * std::pow(1.2, -5));
}

TEST(SphereFlows, LockedBoundaryStaysPut) {
  const auto o =
      run(json{{"mesh", "open_cylinder:n_around=32,n_along=16"}, {"dt", 1e-2}, {"steps", 5}});
  ASSERT_EQ(o.result["status"], "ok");
  const MeshSource src = load_mesh_spec("open_cylinder:n_around=32,n_along=16");
  const auto boundary = boundary_vertices(src.mesh);
  ASSERT_FALSE(boundary.empty());
  for (int v : boundary) EXPECT_EQ(o.final_mesh.vertices.row(v), src.mesh.vertices.row(v));
  // Interior vertices moved (towards the axis: MCF shrinks the cylinder's waist).
  EXPECT_GT((o.final_mesh.vertices - src.mesh.vertices).norm(), 1e-3);
}

TEST(SphereFlows, PinchStopsCleanly) {
  // A dumbbell's neck pinches under MCF with a large step: the flow stops, reports the step
  // and the reason, and never aborts.
  const auto o = run(json{{"mesh", "dumbbell:resolution=32"}, {"dt", 0.2}, {"steps", 50}});
  EXPECT_EQ(o.result["status"], "singular");
  EXPECT_LT(o.result["stop"]["step"].get<int>(), 50);
  EXPECT_FALSE(o.result["stop"]["reason"].get<std::string>().empty());
}

TEST(SphereFlows, UnstableExplicitStepStopsAsDiverged) {
  // Beyond its stability limit (~h²) explicit Euler amplifies the highest frequencies and the
  // area grows: the flow stops and says why, instead of producing a plausible-looking radius.
  const auto o = run(json{{"mesh", "icosphere:level=3"},
                          {"integrator", "explicit-euler"},
                          {"dt", 0.01},
                          {"steps", 50}});
  EXPECT_EQ(o.result["status"], "singular");
  EXPECT_NE(o.result["stop"]["reason"].get<std::string>().find("diverged"), std::string::npos);
  // The stopping step keeps its seconds and the area that stopped it, as every step does.
  const auto& last_step = o.result["steps"].back();
  EXPECT_TRUE(last_step.contains("seconds") && last_step["seconds"].contains("total"))
      << last_step.dump();
  EXPECT_GT(last_step["area"].get<double>(),
            1.05 * o.result["steps"][o.result["steps"].size() - 2]["area"].get<double>());
  const auto stable = run(json{{"mesh", "icosphere:level=3"},
                               {"integrator", "explicit-euler"},
                               {"dt", 5e-4},
                               {"steps", 50}});
  EXPECT_EQ(stable.result["status"], "ok");
}

TEST(SphereFlows, NormalizationKeepsUnitArea) {
  const auto o = run(json{{"mesh", "icosphere:level=3,radius=2"},
                          {"normalize_area", true},
                          {"dt", 1e-2},
                          {"steps", 5}});
  const Positions& V = o.final_mesh.vertices;
  EXPECT_NEAR(surface_area(o.final_mesh), 1.0, 1e-12);
  EXPECT_LT(V.colwise().mean().norm(), 1e-12);
}

// Temporal order on MCF, measured as docs/design.md "Conventions" says: against a run with a much
// smaller δ on the same mesh, so the spatial error cancels (against sqrt(1-4t) it puts a floor
// under it).
double temporal_error(const std::string& integrator, double dt, double T, bool extrapolate,
                      const Positions& reference, const std::string& mesh) {
  const auto o = run(json{{"mesh", mesh},
                          {"integrator", integrator},
                          {"extrapolate", extrapolate},
                          {"dt", dt},
                          {"steps", int(std::lround(T / dt))}});
  EXPECT_EQ(o.result["status"], "ok") << integrator;
  return std::abs(mean_radius(o.final_mesh.vertices) - mean_radius(reference));
}

double order(const std::string& integrator, double dt, double T, bool extrapolate,
             const std::string& mesh) {
  // Reference: Crank-Nicolson (second order) at δ/32, shared by the schemes tested at δ.
  static std::map<std::tuple<std::string, double, double>, Positions> references;
  auto& ref = references[{mesh, dt, T}];
  if (ref.rows() == 0)
    ref = run(json{{"mesh", mesh},
                   {"integrator", "crank-nicolson"},
                   {"dt", dt / 32},
                   {"steps", int(std::lround(T / (dt / 32)))}})
              .final_mesh.vertices;
  const double e1 = temporal_error(integrator, dt, T, extrapolate, ref, mesh);
  const double e2 = temporal_error(integrator, dt / 2, T, extrapolate, ref, mesh);
  return std::log2(e1 / e2);
}

TEST(SphereFlows, TemporalOrders) {
  const std::string mesh = "icosphere:level=3";
  EXPECT_NEAR(order("semi-implicit", 0.01, 0.1, true, mesh), 1.0, 0.15);
  EXPECT_NEAR(order("crank-nicolson", 0.01, 0.1, true, mesh), 2.0, 0.25);
  EXPECT_NEAR(order("bdf2", 0.01, 0.1, true, mesh), 2.0, 0.25);
  EXPECT_NEAR(order("crank-nicolson", 0.01, 0.1, false, mesh), 1.0, 0.25);
  // Explicit schemes need δ below their stability limit (~h²) on this mesh; the truncated
  // Neumann series (1 - z + z² per eigenvalue) has the smallest one.
  EXPECT_NEAR(order("explicit-euler", 5e-4, 0.02, true, mesh), 1.0, 0.15);
  EXPECT_NEAR(order("taylor2", 5e-4, 0.02, true, mesh), 1.0, 0.25);
  EXPECT_NEAR(order("neumann2", 5e-4, 0.02, true, mesh), 1.0, 0.15);
}

TEST(SphereFlows, SecondOrderSchemesBeatEulerAgainstTheContinuousRadius) {
  // Against sqrt(1-4t) itself, on a fine mesh: at δ = 0.01 the second-order schemes' error is
  // far below semi-implicit Euler's (the spatial floor is ~1e-4 here).
  const json base = {{"mesh", "icosphere:level=5"}, {"dt", 0.01}, {"steps", 10}};
  auto err = [&](const char* name) {
    json j = base;
    j["integrator"] = name;
    const auto o = run(j);
    return std::abs(mean_radius(o.final_mesh.vertices) - std::sqrt(1 - 4 * 0.1));
  };
  const double euler = err("semi-implicit");
  EXPECT_LT(err("crank-nicolson"), 0.2 * euler);
  EXPECT_LT(err("bdf2"), 0.2 * euler);
}

}  // namespace
}  // namespace mcf

namespace mcf {
namespace {

// The cMCF paper's Table 1 for the infinite cylinder of radius 1: MCF r = sqrt(1-2t), heat
// r = exp(-t), cMCF r = 1 - t. The middle ring of a long open cylinder (ends held fixed far
// away) follows them; the three differ by a few 1e-3 at t = 0.1.
double middle_radius(const std::string& flow) {
  const std::string mesh = "open_cylinder:radius=1,length=12,n_around=64,n_along=96";
  const auto o =
      testing::run(nlohmann::json{{"mesh", mesh}, {"flow", flow}, {"dt", 1e-3}, {"steps", 100}});
  EXPECT_EQ(o.result["status"], "ok");
  const Positions& V = o.final_mesh.vertices;
  double sum = 0;
  int count = 0;
  const double zmid = 0.5 * (V.col(2).minCoeff() + V.col(2).maxCoeff());
  for (Eigen::Index i = 0; i < V.rows(); ++i)
    if (std::abs(V(i, 2) - zmid) < 0.05) {
      sum += std::hypot(V(i, 0), V(i, 1));
      ++count;
    }
  EXPECT_GT(count, 0);
  // The flow reports the same ring (the input's vertices nearest half height) and the cylinder's
  // semi-implicit recursion and continuous radius (flows/cylinder_reference.h), checked here
  // against this test's own formulas.
  const auto& c = o.result["steps"].back()["cylinder"];
  EXPECT_EQ(c["ring_vertices"], count) << flow;
  EXPECT_NEAR(c["ring_radius"].get<double>(), sum / count, 1e-12) << flow;
  double r = 1;
  for (int n = 0; n < 100; ++n)
    r = flow == "mcf"    ? r * r * r / (r * r + 1e-3)
        : flow == "cmcf" ? r * r / (r + 1e-3)
                         : r / (1 + 1e-3);
  EXPECT_NEAR(c["radius_semi_implicit"].get<double>(), r, 1e-14) << flow;
  const double t = 0.1, continuous = flow == "mcf"    ? std::sqrt(1 - 2 * t)
                                     : flow == "cmcf" ? 1 - t
                                                      : std::exp(-t);
  EXPECT_NEAR(c["radius_continuous"].get<double>(), continuous, 1e-14) << flow;
  return sum / count;
}

TEST(CylinderFlows, RecordedOnlyForOpenCylinders) {
  // An open cylinder is never normalised (its boundary is held: FlowConfig's
  // NormalizeAreaIsRefusedOnAnOpenSurface), so its analytic radius always applies.
  EXPECT_THROW(
      testing::run(nlohmann::json{
          {"mesh", "open_cylinder:n_around=16,n_along=8"}, {"steps", 1}, {"normalize_area", true}}),
      ConfigError);
  const auto sphere = testing::run(nlohmann::json{{"mesh", "icosphere:level=1"}, {"steps", 1}});
  EXPECT_FALSE(sphere.result["steps"][0].contains("cylinder"));
  // Radius 0.5: the recursion uses r0 (cMCF: r_n² / (r_n + δ/r0)).
  const auto half =
      testing::run(nlohmann::json{{"mesh", "open_cylinder:radius=0.5,n_around=16,n_along=8"},
                                  {"flow", "cmcf"},
                                  {"steps", 1},
                                  {"dt", 1e-2}});
  EXPECT_NEAR(half.result["steps"][0]["cylinder"]["radius_semi_implicit"].get<double>(),
              0.25 / (0.5 + 1e-2 / 0.5), 1e-15);
  EXPECT_NEAR(half.result["steps"][0]["cylinder"]["radius_continuous"].get<double>(),
              0.5 - 1e-2 / 0.5, 1e-15);
}

TEST(CylinderFlows, RadiiFollowTheCmcfPapersTable) {
  const double t = 0.1;
  EXPECT_NEAR(middle_radius("mcf"), std::sqrt(1 - 2 * t), 1.5e-3);
  EXPECT_NEAR(middle_radius("heat"), std::exp(-t), 1.5e-3);
  EXPECT_NEAR(middle_radius("cmcf"), 1 - t, 1.5e-3);
}

}  // namespace
}  // namespace mcf
