#include "flows/stabilization.h"

namespace mcf {

double stabilization_rho(double c, double a, double b, const SparseRef& M, const SparseRef& K,
                         const SparseRef& S) {
  const double s = diagonal_sum(S);
  if (!(s > 0.0)) return 0.0;
  return c * (a * diagonal_sum(M) + b * diagonal_sum(K)) / s;
}

}  // namespace mcf
