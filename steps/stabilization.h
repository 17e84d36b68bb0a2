#pragma once
// The normal-gradient stabilization of a flow step (docs/octree-multigrid.md, "Stabilization").
// A step's linear solve (a M + b K) Y = R, with Y held at F on some rows, is solved for the
// increment Δ = Y - F with the band's normal-gradient matrix S (Basis::normal_gradient) added:
//   (a M + b K + ρ S) Δ = R - (a M + b K) F + ρ S Δ̂,        Δ = 0 on the held rows,
// where Δ̂ is the increment predicted from the previous step (steps/predicted_start.h, also the
// solver's start). S vanishes on
// fields constant along the surface's normals and the term acts on Δ - Δ̂ only, never on a
// position: the identity's extension has n·∇x = n ≠ 0, and a term on Y itself would pull the
// surface every step.

#include "bases/basis.h"
#include "steps/predicted_start.h"
#include "steps/reduced_system.h"

namespace mcf {

/// ρ = c tr(a M + b K) / tr(S): the term's diagonal is c times the system's on average, so c
/// means the same at every depth and time step. 0 when S has no positive diagonal.
double stabilization_rho(double c, double a, double b, const SparseRef& M, const SparseRef& K,
                         const SparseRef& S);

/// A flow's stabilized solves at weight c (the basis row's `stabilization`,
/// config/basis_registry.h): each step's solve made one for the increment, as above.
class StabilizedSolve {
 public:
  explicit StabilizedSolve(double weight) : weight_(weight) {}

  /// Y = F + Δ with F the held values (the current coefficients when Y is a position, zero when it
  /// is a velocity) and Δ̂ = warm - F, the increment the solver starts from, as the prediction
  /// (for a position, the previous step's increment: the integrators start position solves at
  /// 2 X_n - X_{n-1}). Throws std::logic_error when the basis has no normal-gradient matrix.
  Coefficients solve(ReducedSystem& system, const Basis& basis, double a, double b,
                     const Coefficients& R, const Coefficients& F, const Coefficients& warm);
  /// ρ of the last solve (0 before the first).
  double rho() const { return rho_; }

 private:
  double weight_;
  double rho_ = 0.0;
  bool started_ = false;  ///< a solve ran (the start-up is the first one's)
  PredictedStart start_;  ///< the prediction's buffers, reused from solve to solve
  /// The first solve's passes: the flow's first step has no previous increment to predict from,
  /// so its solve starts from zero and an iterative solver runs until the residual is down to
  /// kStartUpTolerance (what it leaves of that increment would stay in the surface; later steps
  /// start from a prediction and only remove its change).
  static constexpr double kStartUpTolerance = 1e-8;
  static constexpr int kStartUpPasses = 20;
};

}  // namespace mcf
