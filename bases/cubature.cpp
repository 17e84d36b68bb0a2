#include "bases/cubature.h"

#include <stdexcept>
#include <string>

namespace mcf {
namespace {

void add_orbit3(CubatureRule& r, double a, double w) {  // (a, b, b) and permutations
  const double b = 0.5 * (1.0 - a);
  r.points.push_back({a, b, b});
  r.points.push_back({b, a, b});
  r.points.push_back({b, b, a});
  for (int i = 0; i < 3; ++i) r.weights.push_back(w);
}

void add_orbit6(CubatureRule& r, double a, double b, double w) {  // (a, b, c) all permutations
  const double c = 1.0 - a - b;
  const double p[6][3] = {{a, b, c}, {a, c, b}, {b, a, c}, {b, c, a}, {c, a, b}, {c, b, a}};
  for (const auto& q : p) {
    r.points.push_back({q[0], q[1], q[2]});
    r.weights.push_back(w);
  }
}

CubatureRule make_rule(int order) {
  CubatureRule r;
  r.order = order;
  switch (order) {
    case 1:
      r.degree = 1;
      r.points.push_back({1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0});
      r.weights.push_back(1.0);
      break;
    case 3:
      r.degree = 2;
      add_orbit3(r, 2.0 / 3.0, 1.0 / 3.0);
      break;
    case 6:
      // D. A. Dunavant, "High degree efficient symmetrical Gaussian quadrature rules for the
      // triangle", IJNME 21 (1985), rule of degree 6 with 12 points.
      r.degree = 6;
      add_orbit3(r, 0.501426509658179, 0.116786275726379);
      add_orbit3(r, 0.873821971016996, 0.050844906370207);
      add_orbit6(r, 0.053145049844817, 0.310352451033784, 0.082851075618374);
      break;
    default:
      throw std::invalid_argument("cubature_rule: order must be 1, 3 or 6, got " +
                                  std::to_string(order));
  }
  // Normalise so the weights sum to 1 exactly up to rounding (the tabulated values are given to
  // 15 digits).
  double s = 0.0;
  for (double w : r.weights) s += w;
  for (double& w : r.weights) w /= s;
  return r;
}

}  // namespace

const CubatureRule& cubature_rule(int order) {
  static const CubatureRule r1 = make_rule(1), r3 = make_rule(3), r6 = make_rule(6);
  switch (order) {
    case 1:
      return r1;
    case 3:
      return r3;
    case 6:
      return r6;
    default:
      throw std::invalid_argument("cubature_rule: order must be 1, 3 or 6, got " +
                                  std::to_string(order));
  }
}

}  // namespace mcf
