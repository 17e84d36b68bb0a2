#pragma once
// Metrics of docs/experiments.md "Metrics" beyond those the flow records itself (radial error,
// residuals, step difference, timings): Metro-style mesh distance, quasi-conformal error,
// sphericity.

#include "datasets/mesh.h"

#include <cstdint>

namespace mcf {

/// One-sided and symmetric distances between two surfaces, Metro style: points sampled
/// uniformly (by area) on one surface, exact point-to-triangle distance to the other through a
/// bounding-volume hierarchy. forward: samples of A to B; backward: samples of B to A;
/// symmetric: max of the two (Hausdorff for max), RMS over both sample sets.
struct MeshDistance {
  double rms_forward = 0, max_forward = 0;
  double rms_backward = 0, max_backward = 0;
  double rms = 0, max = 0;
  long long samples = 0;  ///< per side
};
MeshDistance mesh_distance(const TriangleMesh& a, const TriangleMesh& b, long long samples = 100000,
                           std::uint64_t seed = 1);

/// Area-weighted (initial areas) mean over triangles of σ_max/σ_min of the affine map from the
/// initial triangle to the current one (1 for a conformal map; as the cMCF paper's authors log it).
/// Triangles degenerate initially or now (σ_min = 0: infinite ratio) are left out of the mean
/// and of the weights; NaN when no triangle is left. Throws if the vertex counts differ.
double quasi_conformal_error(const TriangleMesh& initial, const Positions& current);

/// Area-weighted standard deviation of the vertex distances to the area-weighted centre,
/// divided by their area-weighted mean (0 for a sphere). Vertex weights = 1/3 of incident area.
double sphericity(const Positions& vertices, const Triangles& faces);

}  // namespace mcf
