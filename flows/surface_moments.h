#pragma once
// The area of a triangulated surface and its area-weighted centroid in one pass, as the flow's
// stop rule and its unit-area normalization need them after every step.
//
// Inputs: V (vertices x 3), F (faces x 3, indices into V). Output: the total area and the sum
// over faces of area × face centroid (divide by the area for the centroid).
// Determinism: faces are summed in fixed chunks whose partial sums are combined in chunk order
// (core/parallel.h, sum_over_chunks), so the result is bitwise the same for any number of
// threads.

#include "datasets/mesh.h"

#include <Eigen/Core>

namespace mcf {

struct SurfaceMoments {
  double area = 0.0;                                                  ///< Σ_f A_f
  Eigen::RowVector3d weighted_centroid = Eigen::RowVector3d::Zero();  ///< Σ_f A_f c_f
  SurfaceMoments& operator+=(const SurfaceMoments& o) {
    area += o.area;
    weighted_centroid += o.weighted_centroid;
    return *this;
  }
};

SurfaceMoments surface_moments(const Positions& V, const Triangles& F);

}  // namespace mcf
