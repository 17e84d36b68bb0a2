// 1-to-4 midpoint subdivision. Edges are found by sorting (not a hash map of pairs): the big
// studies subdivide to ~1M faces and sorting 64-bit keys is both fast and deterministic.

#include "datasets/subdivide.h"

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

namespace mcf {

TriangleMesh subdivide_midpoint(const TriangleMesh& mesh) {
  const Eigen::Index n = mesh.num_vertices();
  const Eigen::Index m = mesh.num_faces();

  // One record per face corner c: the edge from corner c to corner c+1.
  std::vector<std::pair<std::uint64_t, std::int64_t>> edges(3 * m);
  for (Eigen::Index f = 0; f < m; ++f)
    for (int c = 0; c < 3; ++c) {
      std::uint64_t a = static_cast<std::uint32_t>(mesh.faces(f, c));
      std::uint64_t b = static_cast<std::uint32_t>(mesh.faces(f, (c + 1) % 3));
      if (a > b) std::swap(a, b);
      edges[3 * f + c] = {(a << 32) | b, 3 * f + c};
    }
  std::sort(edges.begin(), edges.end());

  // Each distinct edge gets one midpoint vertex, numbered after the original vertices.
  std::vector<int> midpoint(3 * m);
  std::vector<std::uint64_t> unique_edges;
  unique_edges.reserve(3 * m / 2 + 1);
  for (size_t i = 0; i < edges.size(); ++i) {
    if (i == 0 || edges[i].first != edges[i - 1].first) unique_edges.push_back(edges[i].first);
    midpoint[edges[i].second] = static_cast<int>(n + unique_edges.size() - 1);
  }

  TriangleMesh out;
  out.vertices.resize(n + static_cast<Eigen::Index>(unique_edges.size()), 3);
  out.vertices.topRows(n) = mesh.vertices;
  for (size_t e = 0; e < unique_edges.size(); ++e) {
    const auto a = static_cast<Eigen::Index>(unique_edges[e] >> 32);
    const auto b = static_cast<Eigen::Index>(unique_edges[e] & 0xffffffffu);
    out.vertices.row(n + e) = 0.5 * (mesh.vertices.row(a) + mesh.vertices.row(b));
  }

  // Corner triangles keep the parent's orientation; the middle one uses the three midpoints.
  out.faces.resize(4 * m, 3);
  for (Eigen::Index f = 0; f < m; ++f) {
    const int v0 = mesh.faces(f, 0), v1 = mesh.faces(f, 1), v2 = mesh.faces(f, 2);
    const int m01 = midpoint[3 * f], m12 = midpoint[3 * f + 1], m20 = midpoint[3 * f + 2];
    out.faces.row(4 * f + 0) << v0, m01, m20;
    out.faces.row(4 * f + 1) << v1, m12, m01;
    out.faces.row(4 * f + 2) << v2, m20, m12;
    out.faces.row(4 * f + 3) << m01, m12, m20;
  }
  return out;
}

TriangleMesh subdivide_to_faces(const TriangleMesh& mesh, long long target_faces) {
  TriangleMesh out = mesh;
  // An empty mesh would never grow: stop instead of looping forever.
  while (out.num_faces() > 0 && out.num_faces() < target_faces) out = subdivide_midpoint(out);
  return out;
}

}  // namespace mcf
