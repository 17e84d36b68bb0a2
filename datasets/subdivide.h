#pragma once
#include "datasets/mesh.h"

namespace mcf {

/// One 1-to-4 midpoint subdivision (new vertices at edge midpoints, not projected). Original
/// vertices keep their indices (0..n-1).
TriangleMesh subdivide_midpoint(const TriangleMesh& mesh);
/// Repeats subdivide_midpoint until the face count reaches at least `target_faces`.
TriangleMesh subdivide_to_faces(const TriangleMesh& mesh, long long target_faces);

}  // namespace mcf
