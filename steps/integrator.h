#pragma once
// Time integrators (docs/design.md "Time integrators"; A = -M⁻¹K).

#include "steps/step_context.h"

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

/// explicit-euler, semi-implicit, crank-nicolson, bdf2, taylor2, neumann2.
const std::vector<std::string>& integrator_names();
/// Whether the integrator reads `extrapolate` (the two-step schemes: operators at the
/// extrapolated X* or frozen at X_n).
bool integrator_reads_extrapolate(const std::string& name);
/// `extrapolate`: two-step schemes evaluate M, K at the extrapolated X* (second order on MCF);
/// false freezes them at X_n (first order). Throws std::invalid_argument on an unknown name.
std::unique_ptr<Integrator> make_integrator(const std::string& name, bool extrapolate);

}  // namespace mcf
