#pragma once
// A mesh's faces reordered for locality: by their smallest vertex index, so that a pass over the
// faces reads vertices in (nearly) increasing order. With vertices numbered so that neighbours
// are close (bases/vertex_ordering.h), consecutive faces then share most of their corners.
//
// Inputs: F (faces x 3, indices into [0, vertices)). Output: the same rows, permuted; faces with
// the same smallest vertex keep their order (a stable counting sort, linear time).

#include "datasets/mesh.h"

namespace mcf {

Triangles faces_by_smallest_vertex(const Triangles& F, Eigen::Index vertices);

}  // namespace mcf
