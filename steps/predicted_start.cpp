#include "steps/predicted_start.h"

#include "solvers/symmetric_multiply.h"

#include <algorithm>
#include <cmath>

namespace mcf {

void predicted_start(const MatrixSum& A, const Coefficients& R, const Coefficients& F,
                     const Coefficients& P, PredictedStart& s) {
  const Eigen::Index n = F.rows();
  Eigen::MatrixXd& X = s.columns;
  Eigen::MatrixXd& Y = s.images;
  X.resize(n, 6);
  Y.resize(n, 6);
  X.leftCols(3) = F;
  X.rightCols(3) = P - F;
  symmetric_multiply(A, X, Y);
  s.residual.resize(n, 3);
  s.residual.noalias() = R - Y.leftCols(3);
  const double aa = Y.rightCols(3).squaredNorm();
  const double ra = (s.residual.array() * Y.rightCols(3).array()).sum();
  s.theta = aa > 0.0 && std::isfinite(ra / aa) ? std::clamp(ra / aa, 0.0, 1.0) : 0.0;
  s.increment.resize(n, 3);
  s.increment.noalias() = s.theta * X.rightCols(3);
}

PredictedStart predicted_start(const MatrixSum& A, const Coefficients& R, const Coefficients& F,
                               const Coefficients& P) {
  PredictedStart s;
  predicted_start(A, R, F, P, s);
  return s;
}

}  // namespace mcf
