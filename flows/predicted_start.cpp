#include "flows/predicted_start.h"

#include "solvers/symmetric_multiply.h"

#include <algorithm>
#include <cmath>

namespace mcf {

PredictedStart predicted_start(const MatrixSum& A, const Coefficients& R, const Coefficients& F,
                               const Coefficients& P) {
  const Eigen::Index n = F.rows();
  PredictedStart s;
  Eigen::MatrixXd X(n, 6), Y;
  X.leftCols(3) = F;
  X.rightCols(3) = P - F;
  symmetric_multiply(A, X, Y);
  s.residual = R - Y.leftCols(3);
  const double aa = Y.rightCols(3).squaredNorm();
  const double ra = (s.residual.array() * Y.rightCols(3).array()).sum();
  s.theta = aa > 0.0 && std::isfinite(ra / aa) ? std::clamp(ra / aa, 0.0, 1.0) : 0.0;
  s.increment = s.theta * X.rightCols(3);
  return s;
}

}  // namespace mcf
