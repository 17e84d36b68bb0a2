#pragma once
// Analytic radius of the middle ring of a long open cylinder of radius r0 (axis z), the infinite
// cylinder of the cMCF paper's Table 1 (Kazhdan, Solomon & Ben-Chen 2012). On a cylinder of
// radius r, K x = (1/r²) M x for the circular coordinates and M scales with r, so the
// semi-implicit step (M_n + δ K) X_{n+1} = M_n X_n gives
//   MCF  (K_n):          r_{n+1} = r_n³ / (r_n² + δ)          continuous: sqrt(r0² - 2t)
//   cMCF (K_0 kept):     r_{n+1} = r_n² / (r_n + δ/r0)        continuous: r0 - t/r0
//   heat (M_0 and K_0):  r_{n+1} = r_n / (1 + δ/r0²)          continuous: r0 exp(-t/r0²)
// The ring far from the fixed ends follows them (tests/flows/test_sphere_flows.cpp,
// CylinderFlows); near the ends the fixed boundary holds the surface back.

#include "datasets/mesh.h"

#include <cmath>
#include <limits>
#include <vector>

namespace mcf {

struct CylinderReference {
  double r0 = 1.0;
  bool keeps_mass = false;         ///< M_0 for every step (heat flow)
  bool keeps_stiffness = false;    ///< K_0 for every step (cMCF, heat flow)
  double discrete = 1.0;           ///< semi-implicit recursion after the steps so far
  std::vector<Eigen::Index> ring;  ///< the input's vertices nearest to half height

  /// The flow is given by the operators of t = 0 it keeps (config/flow_registry.h).
  CylinderReference(double radius, bool kept_mass, bool kept_stiffness, const Positions& X0)
      : r0(radius), keeps_mass(kept_mass), keeps_stiffness(kept_stiffness), discrete(radius) {
    const double zmid = 0.5 * (X0.col(2).minCoeff() + X0.col(2).maxCoeff());
    double nearest = std::numeric_limits<double>::infinity();
    for (Eigen::Index i = 0; i < X0.rows(); ++i)
      nearest = std::min(nearest, std::abs(X0(i, 2) - zmid));
    for (Eigen::Index i = 0; i < X0.rows(); ++i)
      if (std::abs(X0(i, 2) - zmid) <= nearest + 1e-9 * r0) ring.push_back(i);
  }
  void advance(double dt) {
    if (keeps_mass)
      discrete = discrete / (1.0 + dt / (r0 * r0));
    else if (keeps_stiffness)
      discrete = discrete * discrete / (discrete + dt / r0);
    else
      discrete = discrete * discrete * discrete / (discrete * discrete + dt);
  }
  double continuous(double t) const {
    if (keeps_mass) return r0 * std::exp(-t / (r0 * r0));
    if (keeps_stiffness) return r0 - t / r0;
    const double s = r0 * r0 - 2.0 * t;
    return s > 0 ? std::sqrt(s) : 0.0;
  }
  /// Mean distance of the ring's vertices from the z axis.
  double ring_radius(const Positions& V) const {
    double sum = 0;
    for (Eigen::Index i : ring) sum += std::hypot(V(i, 0), V(i, 1));
    return ring.empty() ? 0.0 : sum / double(ring.size());
  }
};

}  // namespace mcf
