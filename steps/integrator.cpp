#include "steps/integrator.h"

#include <stdexcept>

namespace mcf {
namespace {

// Where an iterative solver starts a position solve: the previous step's increment added once
// more, 2 X_n - X_{n-1} (the linear extrapolation; X_n on the first step). The increment changes
// by a relative O(δ) from one step to the next, so the start is that much closer than X_n.
Coefficients extrapolated_start(const StepContext& c) {
  if (!c.previous()) return c.current();
  return 2.0 * c.current() - *c.previous();
}

// M X' = M X_n - δ K X_n (forward Euler; stable only for small δ).
class ExplicitEuler final : public Integrator {
 public:
  std::string name() const override { return "explicit-euler"; }
  Coefficients step(StepContext& c) override {
    const Coefficients& x = c.current();
    c.evaluate_operators(x);
    // Solve for the velocity so the locked rows simply get zero.
    const Coefficients v = c.solve(1.0, 0.0, -c.apply_stiffness(x), Coefficients::Zero(x.rows(), 3),
                                   Coefficients::Zero(x.rows(), 3));
    return x + c.dt() * v;
  }
};

// (M + δK) X' = M X_n (Desbrun et al. 1999; Chuang & Kazhdan Eq. 2 without the δ/2 typo).
class SemiImplicitEuler final : public Integrator {
 public:
  std::string name() const override { return "semi-implicit"; }
  Coefficients step(StepContext& c) override {
    const Coefficients& x = c.current();
    c.evaluate_operators(x);
    return c.solve(1.0, c.dt(), c.apply_mass(x), x, extrapolated_start(c));
  }
};

// Two-step schemes start with one semi-implicit Euler step (docs/design.md "Time integrators").
class TwoStep : public Integrator {
 public:
  explicit TwoStep(bool extrapolate) : extrapolate_(extrapolate) {}
  Coefficients step(StepContext& c) override {
    if (!c.previous()) return SemiImplicitEuler().step(c);
    return two_step(c, c.current(), *c.previous());
  }
  bool uses_previous() const override { return true; }

 protected:
  virtual Coefficients two_step(StepContext& c, const Coefficients& x,
                                const Coefficients& x_prev) = 0;
  bool extrapolate_;
};

// (M + δ/2 K) X' = (M - δ/2 K) X_n with operators at X* = (3X_n - X_{n-1})/2, the midpoint.
class CrankNicolson final : public TwoStep {
 public:
  using TwoStep::TwoStep;
  std::string name() const override { return "crank-nicolson"; }

 protected:
  Coefficients two_step(StepContext& c, const Coefficients& x,
                        const Coefficients& x_prev) override {
    c.evaluate_operators(extrapolate_ ? Coefficients(1.5 * x - 0.5 * x_prev) : x);
    const double h = 0.5 * c.dt();
    return c.solve(1.0, h, c.apply_mass(x) - h * c.apply_stiffness(x), x, extrapolated_start(c));
  }
};

// (3/2 M + δK) X' = M (2X_n - X_{n-1}/2) with operators at X* = 2X_n - X_{n-1}.
class Bdf2 final : public TwoStep {
 public:
  using TwoStep::TwoStep;
  std::string name() const override { return "bdf2"; }

 protected:
  Coefficients two_step(StepContext& c, const Coefficients& x,
                        const Coefficients& x_prev) override {
    c.evaluate_operators(extrapolate_ ? Coefficients(2.0 * x - x_prev) : x);
    const Coefficients target = 2.0 * x - 0.5 * x_prev;
    return c.solve(1.5, c.dt(), c.apply_mass(target), x, extrapolated_start(c));
  }
};

// X' = X_n + δ A X_n + κ δ² A² X_n with A = -M⁻¹K: κ = 1/2 is the second-order Taylor scheme,
// κ = 1 the truncated Neumann series of backward Euler (SGI note, eq. ***).
class Series2 final : public Integrator {
 public:
  Series2(std::string name, double kappa) : name_(std::move(name)), kappa_(kappa) {}
  std::string name() const override { return name_; }
  Coefficients step(StepContext& c) override {
    const Coefficients& x = c.current();
    c.evaluate_operators(x);
    const Coefficients zero = Coefficients::Zero(x.rows(), 3);
    const Coefficients ax = c.solve(1.0, 0.0, -c.apply_stiffness(x), zero, zero);
    const Coefficients aax = c.solve(1.0, 0.0, -c.apply_stiffness(ax), zero, zero);
    return x + c.dt() * ax + kappa_ * c.dt() * c.dt() * aax;
  }

 private:
  std::string name_;
  double kappa_;
};

}  // namespace

const std::vector<IntegratorRow>& integrator_table() {
  static const std::vector<IntegratorRow> table = {
      {"explicit-euler", "forward Euler, M X' = M X_n - δ K X_n: stable only for δ of order h²",
       false, [](bool) { return std::make_unique<ExplicitEuler>(); }},
      {"semi-implicit",
       "backward Euler with the operators at X_n, (M + δK) X' = M X_n: first order", false,
       [](bool) { return std::make_unique<SemiImplicitEuler>(); }},
      {"crank-nicolson",
       "the trapezoidal rule, (M + δ/2 K) X' = (M - δ/2 K) X_n with the operators at the "
       "extrapolated midpoint X*: second order",
       true, [](bool extrapolate) { return std::make_unique<CrankNicolson>(extrapolate); }},
      {"bdf2",
       "the two-step backward difference, (3/2 M + δK) X' = M (2X_n - X_{n-1}/2) with the "
       "operators at X* = 2X_n - X_{n-1}: second order",
       true, [](bool extrapolate) { return std::make_unique<Bdf2>(extrapolate); }},
      {"taylor2", "X' = X_n + δ A X_n + δ²/2 A² X_n with A = -M⁻¹K: second order on heat flow only",
       false, [](bool) { return std::make_unique<Series2>("taylor2", 0.5); }},
      {"neumann2",
       "backward Euler's series cut after δ², X' = X_n + δ A X_n + δ² A² X_n: first order", false,
       [](bool) { return std::make_unique<Series2>("neumann2", 1.0); }},
  };
  return table;
}

namespace {

const IntegratorRow* find_row(const std::string& name) {
  for (const IntegratorRow& row : integrator_table())
    if (row.name == name) return &row;
  return nullptr;
}

}  // namespace

const IntegratorRow& integrator_row(const std::string& name) {
  if (const IntegratorRow* row = find_row(name)) return *row;
  throw std::invalid_argument("unknown integrator \"" + name + "\"");
}

const std::vector<std::string>& integrator_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const IntegratorRow& row : integrator_table()) n.push_back(row.name);
    return n;
  }();
  return names;
}

bool integrator_reads_extrapolate(const std::string& name) {
  const IntegratorRow* row = find_row(name);
  return row && row->reads_extrapolate;
}

std::unique_ptr<Integrator> make_integrator(const std::string& name, bool extrapolate) {
  return integrator_row(name).make(extrapolate);
}

}  // namespace mcf
