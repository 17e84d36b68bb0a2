#pragma once
// Analytic radii of a sphere of radius r0 under each flow (docs/design.md "Conventions"):
//   MCF and cMCF, semi-implicit:  r_{n+1} = r_n³ / (r_n² + 2δ)    continuous: r(t) = sqrt(r0² - 4t)
//   heat flow (operators of t=0): r_{n+1} = r_n / (1 + 2δ/r0²)     continuous: r0 exp(-2t/r0²)
// (On a sphere K x = (2/r²) M x; cMCF keeps K_0 but M scales with the area, so its radius
// follows MCF's exactly.)

#include "datasets/mesh.h"

#include <cmath>
#include <string>

namespace mcf {

struct SphereReference {
  double r0 = 1.0;
  bool heat = false;
  double discrete = 1.0;  ///< semi-implicit recursion after the steps so far

  SphereReference(double radius, bool heat_flow) : r0(radius), heat(heat_flow), discrete(radius) {}
  void advance(double dt) {
    discrete = heat ? discrete / (1.0 + 2.0 * dt / (r0 * r0))
                    : discrete * discrete * discrete / (discrete * discrete + 2.0 * dt);
  }
  double continuous(double t) const {
    if (heat) return r0 * std::exp(-2.0 * t / (r0 * r0));
    const double s = r0 * r0 - 4.0 * t;
    return s > 0 ? std::sqrt(s) : 0.0;
  }
};

struct RadialError {
  double rms = 0, max = 0;
};

/// RMS and max of | |v| - r | over the vertices (sphere centred at the origin).
inline RadialError radial_error(const Positions& V, double r) {
  RadialError e;
  double sum = 0;
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    const double d = std::abs(V.row(i).norm() - r);
    sum += d * d;
    e.max = std::max(e.max, d);
  }
  e.rms = V.rows() ? std::sqrt(sum / double(V.rows())) : 0.0;
  return e;
}

}  // namespace mcf
