#pragma once
// Closest-point queries against a triangle soup: an axis-aligned bounding-box tree (median split)
// and Ericson's exact point-to-triangle closest point. Used by the Metro-style mesh distance.

#include "datasets/mesh.h"

#include <limits>
#include <vector>

namespace mcf {

/// Closest point to p on the triangle (a, b, c), exact up to rounding (Ericson, Real-Time
/// Collision Detection §5.1.5: classify p against the Voronoi regions of the vertices, edges and
/// face). A degenerate triangle (coincident corners, or collinear up to rounding: sin²θ <= 1e-12
/// at a) is taken as its three edges, whose nearest point is returned: exact for a segment or a
/// point, and off by at most the inradius (< 5e-7 of the shorter edge at a) for a thin sliver.
Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                          const Eigen::Vector3d& b, const Eigen::Vector3d& c);

struct ClosestHit {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  double squared_distance = std::numeric_limits<double>::infinity();
  int triangle = -1;  ///< -1 when nothing was found (empty tree or nothing nearer than the bound)
};

/// Bounding-volume hierarchy over the triangles of a mesh. Built once in O(n log n) (median split
/// on the longest axis of the centroid bounds with nth_element); queries are read-only, so any
/// number of threads may query one tree at the same time.
class TriangleBvh {
 public:
  TriangleBvh(const Positions& vertices, const Triangles& faces);

  /// Closest point on the mesh to p. Only triangles strictly nearer than sqrt(bound_squared) are
  /// considered (pass a known upper bound to prune more). Ties go to the first triangle met in a
  /// fixed traversal order, so the answer is deterministic.
  ClosestHit closest(const Eigen::Vector3d& p,
                     double bound_squared = std::numeric_limits<double>::infinity()) const;

  /// The same answer by testing every triangle (reference for tests, and for tiny meshes).
  ClosestHit closest_brute_force(const Eigen::Vector3d& p) const;

  std::size_t num_nodes() const { return nodes_.size(); }
  int depth() const { return depth_; }

 private:
  /// Leaves hold `count` > 0 triangles starting at `first` in order_; an inner node has
  /// count == 0, its left child right after it (depth-first layout) and its right child at `first`.
  struct Node {
    Eigen::Vector3d lo, hi;
    int first = 0, count = 0;
  };
  int build(int begin, int end, int depth, const Positions& vertices, const Triangles& faces,
            const std::vector<Eigen::Vector3d>& centroids);
  void test_triangle(int slot, const Eigen::Vector3d& p, ClosestHit& best) const;

  // Corners copied in leaf order: the tree owns its data (no dangling mesh reference) and a
  // leaf's triangles are contiguous in memory.
  std::vector<Eigen::Vector3d> corners_;  ///< 3 per triangle, in order_ order
  std::vector<int> order_;  ///< original triangle indices, permuted so each leaf is contiguous
  std::vector<Node> nodes_;
  int depth_ = 0;
};

}  // namespace mcf
