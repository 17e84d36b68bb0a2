#pragma once
// Triangle cubature rules in barycentric coordinates (docs/design.md "The octree basis").
// Weights sum to 1, so  ∫_T f dA ≈ |T| Σ_q ω_q f(Σ_i b_qi v_i).

#include <array>
#include <vector>

namespace mcf {

struct CubatureRule {
  int order = 0;   ///< number of points (the option value: 1, 3 or 6 selects the rule)
  int degree = 0;  ///< polynomial degree integrated exactly
  std::vector<std::array<double, 3>> points;  ///< barycentric coordinates, each summing to 1
  std::vector<double> weights;                ///< summing to 1
  int size() const { return static_cast<int>(weights.size()); }
};

/// order 1: centroid (degree 1); order 3: the paper's rule (2/3,1/6,1/6)+perms, weights 1/3
/// (degree 2); order 6: Dunavant's 12-point degree-6 rule. Throws std::invalid_argument otherwise.
const CubatureRule& cubature_rule(int order);

}  // namespace mcf
