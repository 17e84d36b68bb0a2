#pragma once
// Where a step's solve starts. The integrators predict a position solve's solution by linear
// extrapolation, P = 2 X_n - X_{n-1}; the start is the point of the line from the held values F
// (X_n) to P that fits the step's equations best:
//   F + θ (P - F),   θ ∈ [0, 1] minimizing ||R - A (F + θ (P - F))||  (Frobenius norm),
// A = a M + b K. In a smooth flow θ is close to 1 and an iterative solver only has to remove
// the increment's change from one step to the next; where the flow accelerates (a pinch) the
// extrapolation overshoots and θ falls toward 0, the previous position. The stabilized solve
// takes θ (P - F) as its prediction (steps/stabilization.h).

#include "bases/basis.h"
#include "solvers/linear_solver.h"

namespace mcf {

struct PredictedStart {
  double theta = 0.0;
  Coefficients increment;  ///< θ (P - F)
  Coefficients residual;   ///< R - A F
  /// The fused product's columns [F, P - F] and their images (n x 6 each), kept with the result
  /// so that a caller which keeps one PredictedStart from step to step reuses their memory: fresh
  /// pages cost more than the product's arithmetic on a large mesh.
  Eigen::MatrixXd columns, images;
};

/// One fused pass over A's terms for A F and A (P - F) (six columns), into `s`.
void predicted_start(const MatrixSum& A, const Coefficients& R, const Coefficients& F,
                     const Coefficients& P, PredictedStart& s);

/// The same into a new PredictedStart.
PredictedStart predicted_start(const MatrixSum& A, const Coefficients& R, const Coefficients& F,
                               const Coefficients& P);

}  // namespace mcf
