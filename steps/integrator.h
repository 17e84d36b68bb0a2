#pragma once
// Time integrators (docs/design.md "Time integrators"; A = -M⁻¹K).

#include "steps/step_context.h"

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace mcf {

class Integrator {
 public:
  virtual ~Integrator() = default;
  virtual std::string name() const = 0;
  /// Returns X_{n+1}. Leaves the operators as evaluated for this step.
  virtual Coefficients step(StepContext& ctx) = 0;
  /// Whether step() reads X_{n-1} (ctx.previous()): the flow keeps that copy only then.
  virtual bool uses_previous() const { return false; }
};

/// One value of the config's `integrator`: the table below maps each name to its scheme, as the
/// registries of config/ map solvers and bases.
struct IntegratorRow {
  std::string name;
  std::string help;                ///< one line on the scheme, for --help and docs/flow.md
  bool reads_extrapolate = false;  ///< the two-step schemes: `extrapolate` applies (operators at
                                   ///< the extrapolated X*, or frozen at X_n with false)
  /// The integrator; `extrapolate` as above (read only where reads_extrapolate).
  std::function<std::unique_ptr<Integrator>(bool extrapolate)> make;
};

/// Every integrator, in the order the docs list them.
const std::vector<IntegratorRow>& integrator_table();
/// The row of `name`; throws std::invalid_argument naming it where there is none.
const IntegratorRow& integrator_row(const std::string& name);

/// The table's names: explicit-euler, semi-implicit, crank-nicolson, bdf2, taylor2, neumann2.
const std::vector<std::string>& integrator_names();
/// integrator_row(name).reads_extrapolate; false for a name not in the table.
bool integrator_reads_extrapolate(const std::string& name);
/// integrator_row(name).make(extrapolate): two-step schemes evaluate M, K at the extrapolated X*
/// (second order on MCF); false freezes them at X_n (first order). Throws std::invalid_argument on
/// an unknown name.
std::unique_ptr<Integrator> make_integrator(const std::string& name, bool extrapolate);

}  // namespace mcf
