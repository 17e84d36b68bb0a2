#include "steps/stabilization.h"

#include "solvers/symmetric_multiply.h"
#include "steps/predicted_start.h"

#include <stdexcept>

namespace mcf {

double stabilization_rho(double c, double a, double b, const SparseRef& M, const SparseRef& K,
                         const SparseRef& S) {
  const double s = diagonal_sum(S);
  if (!(s > 0.0)) return 0.0;
  return c * (a * diagonal_sum(M) + b * diagonal_sum(K)) / s;
}

Coefficients StabilizedSolve::solve(ReducedSystem& system, const Basis& basis, double a, double b,
                                    const Coefficients& R, const Coefficients& F,
                                    const Coefficients& warm) {
  const SparseView S = basis.normal_gradient();
  if (S.rows() != basis.dimension())
    throw std::logic_error("stabilized solve: the basis has no normal-gradient matrix");
  const SparseView M = basis.mass(), K = basis.stiffness();
  rho_ = stabilization_rho(weight_, a, b, M, K, S);
  PredictedStart& start = start_;
  predicted_start(MatrixSum(a, M, b, K), R, F, warm, start);
  // R - (a M + b K) F + ρ S Δ̂, and Δ̂ is also where the solver starts.
  Coefficients& rhs = start.residual;
  if (start.theta > 0.0) rhs.noalias() += rho_ * symmetric_multiply(S, start.increment);
  const ReducedSystem::Passes start_up{kStartUpTolerance, kStartUpPasses};
  const bool first = !started_ && start.theta == 0.0;
  started_ = true;
  const ReducedSystem::ExtraTerm term{rho_, S};
  const Coefficients delta = system.solve(a, b, rhs, Coefficients::Zero(F.rows(), 3),
                                          start.increment, &term, first ? &start_up : nullptr);
  return delta + F;
}

}  // namespace mcf
