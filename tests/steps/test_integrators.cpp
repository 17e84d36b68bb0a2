// Integrator formulas on the scalar linear ODE x' = -λ x (M = 1, K = λ): the exact solution is
// x0 exp(-λ t), so the observed orders must be the textbook ones (heat flow is linear, so
// Taylor-2 is second order there while the Neumann series truncation stays first order).

#include "steps/integrator.h"

#include <gtest/gtest.h>

#include <cmath>

namespace mcf {
namespace {

// M = m(X) I and K = λ I, with an optional dependence of the mass on the embedding to make the
// problem nonlinear (m = 1 + μ|X|²), like MCF's area-dependent mass.
class ScalarContext final : public StepContext {
 public:
  ScalarContext(double lambda, double dt, double mu = 0.0) : lambda_(lambda), dt_(dt), mu_(mu) {}
  double dt() const override { return dt_; }
  const Coefficients& current() const override { return x_; }
  const Coefficients* previous() const override { return has_prev_ ? &prev_ : nullptr; }
  void evaluate_operators(const Coefficients& X) override { m_ = 1.0 + mu_ * X.squaredNorm(); }
  Coefficients apply_mass(const Coefficients& X) const override { return m_ * X; }
  Coefficients apply_stiffness(const Coefficients& X) const override { return lambda_ * X; }
  Coefficients solve(double a, double b, const Coefficients& R, const Coefficients&,
                     const Coefficients&) override {
    return R / (a * m_ + b * lambda_);
  }
  void advance(const Coefficients& next) {
    prev_ = x_;
    has_prev_ = true;
    x_ = next;
  }
  Coefficients x_ = Coefficients::Constant(1, 3, 1.0);

 private:
  double lambda_, dt_, mu_, m_ = 1.0;
  Coefficients prev_;
  bool has_prev_ = false;
};

double final_value(const std::string& name, double dt, double T, double mu = 0.0,
                   bool extrapolate = true) {
  auto integrator = make_integrator(name, extrapolate);
  ScalarContext ctx(1.0, dt, mu);
  const int steps = int(std::lround(T / dt));
  for (int i = 0; i < steps; ++i) ctx.advance(integrator->step(ctx));
  return ctx.x_(0, 0);
}

double observed_order(const std::string& name, double mu = 0.0, bool extrapolate = true,
                      double reference = -1) {
  const double T = 1.0;
  const double exact = reference >= 0 ? reference : std::exp(-T);
  const double e1 = std::abs(final_value(name, 0.02, T, mu, extrapolate) - exact);
  const double e2 = std::abs(final_value(name, 0.01, T, mu, extrapolate) - exact);
  return std::log2(e1 / e2);
}

TEST(Integrators, LinearOrders) {
  EXPECT_NEAR(observed_order("explicit-euler"), 1.0, 0.1);
  EXPECT_NEAR(observed_order("semi-implicit"), 1.0, 0.1);
  EXPECT_NEAR(observed_order("neumann2"), 1.0, 0.1);
  EXPECT_NEAR(observed_order("taylor2"), 2.0, 0.1);
  EXPECT_NEAR(observed_order("crank-nicolson"), 2.0, 0.15);
  EXPECT_NEAR(observed_order("bdf2"), 2.0, 0.15);
}

TEST(Integrators, NonlinearNeedsExtrapolation) {
  // With an embedding-dependent mass, CN and BDF2 are second order only when the operators are
  // evaluated at the extrapolated X*; frozen at X_n they drop to first order (docs/design.md
  // "Time integrators").
  const double mu = 0.5, T = 1.0;
  const double reference = final_value("crank-nicolson", 1e-4, T, mu, true);
  EXPECT_NEAR(observed_order("crank-nicolson", mu, true, reference), 2.0, 0.2);
  EXPECT_NEAR(observed_order("bdf2", mu, true, reference), 2.0, 0.2);
  EXPECT_NEAR(observed_order("crank-nicolson", mu, false, reference), 1.0, 0.2);
  EXPECT_NEAR(observed_order("bdf2", mu, false, reference), 1.0, 0.2);
}

TEST(Integrators, ExplicitEulerIsUnstableBeyondItsLimit) {
  // x_{n+1} = (1 - λδ) x_n blows up for δ > 2/λ; the semi-implicit scheme never does.
  EXPECT_GT(std::abs(final_value("explicit-euler", 2.5, 100.0)), 1e3);
  EXPECT_LT(std::abs(final_value("semi-implicit", 2.5, 100.0)), 1.0);
}

TEST(Integrators, UnknownNameThrows) {
  EXPECT_THROW(make_integrator("rk4", true), std::invalid_argument);
}

}  // namespace
}  // namespace mcf

namespace mcf {
namespace {

// The table is the only list of integrators: each row makes the scheme of its name, and the rows
// that take `extrapolate` are exactly the two-step schemes (those that read X_{n-1}).
TEST(IntegratorTable, EachRowMakesItsSchemeAndOnlyTwoStepOnesReadExtrapolate) {
  ASSERT_EQ(integrator_table().size(), integrator_names().size());
  for (const IntegratorRow& row : integrator_table()) {
    EXPECT_FALSE(row.help.empty()) << row.name;
    for (bool extrapolate : {true, false}) {
      const std::unique_ptr<Integrator> integrator = make_integrator(row.name, extrapolate);
      EXPECT_EQ(integrator->name(), row.name);
      EXPECT_EQ(row.reads_extrapolate, integrator->uses_previous()) << row.name;
    }
    EXPECT_EQ(integrator_reads_extrapolate(row.name), row.reads_extrapolate);
  }
  EXPECT_FALSE(integrator_reads_extrapolate("rk4"));
  try {
    integrator_row("rk4");
    ADD_FAILURE() << "rk4 taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("\"rk4\""), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace mcf
