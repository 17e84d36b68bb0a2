#pragma once
// What an integrator may do during one step: evaluate the operators at an embedding, apply them,
// and solve (a M + b K) Y = R with the locked functions held at given values.

#include "bases/basis.h"
#include "solvers/linear_solver.h"

namespace mcf {

class StepContext {
 public:
  virtual ~StepContext() = default;
  virtual double dt() const = 0;
  virtual const Coefficients& current() const = 0;   ///< X_n
  virtual const Coefficients* previous() const = 0;  ///< X_{n-1}, or nullptr on the first step
  /// Assembles M and K at embedding X (what is re-assembled depends on the flow: MCF both, cMCF
  /// mass only, heat neither after the first call).
  virtual void evaluate_operators(const Coefficients& X) = 0;
  virtual Coefficients apply_mass(const Coefficients& X) const = 0;
  virtual Coefficients apply_stiffness(const Coefficients& X) const = 0;
  /// Solves (a M + b K) Y = R. Locked rows of Y take `locked_values` (same rows); `warm` is the
  /// starting guess for iterative solvers. Records the solver report of this step.
  virtual Coefficients solve(double a, double b, const Coefficients& R,
                             const Coefficients& locked_values, const Coefficients& warm) = 0;
};

}  // namespace mcf
