#pragma once
// The edges of a face list, found by sorting one record per face corner: the undirected edge's
// 64-bit key and whether the face runs it from its smaller vertex to its larger one. Records of
// one edge end up adjacent, in face order; a manifold interior edge has two, a boundary edge one.
// Validation (validate.cpp) and orientation (orientation.cpp) both read edges this way.

#include "datasets/mesh.h"

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <utility>
#include <vector>

namespace mcf {

struct EdgeUse {
  std::uint64_t key;  ///< (smaller vertex << 32) | larger vertex
  Eigen::Index face;
  bool forward;  ///< the face runs the edge from its smaller vertex to its larger one
  bool operator<(const EdgeUse& o) const { return key < o.key || (key == o.key && face < o.face); }
};

/// Every corner's record, sorted by edge, then face (a total order: the parallel sort's result
/// does not depend on the threads).
inline std::vector<EdgeUse> sorted_edge_uses(const Triangles& faces) {
  const Eigen::Index m = faces.rows();
  std::vector<EdgeUse> uses(static_cast<std::size_t>(3 * m));
  for (Eigen::Index f = 0; f < m; ++f)
    for (int c = 0; c < 3; ++c) {
      std::uint64_t a = static_cast<std::uint32_t>(faces(f, c));
      std::uint64_t b = static_cast<std::uint32_t>(faces(f, (c + 1) % 3));
      const bool forward = a < b;
      if (!forward) std::swap(a, b);
      uses[static_cast<std::size_t>(3 * f + c)] = {(a << 32) | b, f, forward};
    }
  tbb::parallel_sort(uses.begin(), uses.end());
  return uses;
}

/// The two vertices of an edge key, smaller first.
inline std::array<int, 2> edge_vertices(std::uint64_t key) {
  return {static_cast<int>(key >> 32), static_cast<int>(key & 0xffffffffu)};
}

}  // namespace mcf
