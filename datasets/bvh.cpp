#include "datasets/bvh.h"

#include <algorithm>
#include <numeric>
#include <stdexcept>

namespace mcf {
namespace {

/// Closest point to p on the segment [s, e] (a zero-length one is its point).
Eigen::Vector3d closest_point_on_segment(const Eigen::Vector3d& p, const Eigen::Vector3d& s,
                                         const Eigen::Vector3d& e) {
  const Eigen::Vector3d d = e - s;
  const double len2 = d.squaredNorm();
  if (!(len2 > 0)) return s;
  return s + std::clamp((p - s).dot(d) / len2, 0.0, 1.0) * d;
}

/// Nearest of the closest points on the three edges: the closest point of a degenerate
/// triangle (a segment or a point), which its edges cover.
Eigen::Vector3d closest_point_on_edges(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                       const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  Eigen::Vector3d best = closest_point_on_segment(p, a, b);
  for (const Eigen::Vector3d& q :
       {closest_point_on_segment(p, b, c), closest_point_on_segment(p, a, c)})
    if ((q - p).squaredNorm() < (best - p).squaredNorm()) best = q;
  return best;
}

/// A triangle is taken as degenerate when |ab×ac|² <= kFlat·|ab|²·|ac|², i.e. sin²θ <= kFlat
/// for its angle θ at a (a zero-length edge and a NaN too). Its edges then stand for it: that
/// overestimates the distance by at most its inradius, below sinθ/2 of the shorter edge at a
/// (5e-7 of it here), while the region tests' rounding error grows like 2^-53/sin²θ (about 1e-6 of
/// the edge at sin²θ = 1e-12 against an exact reference, 1e-3 at 1e-15, and O(1) on triangles
/// collinear up to rounding, whose sin²θ is noise of 1e-32 to 1e-20).
constexpr double kFlat = 1e-12;

}  // namespace

Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                          const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  // Ericson's region tests: every branch returns the exact closest point of its Voronoi region,
  // so no projection-then-clamp error appears near edges and vertices.
  const Eigen::Vector3d ab = b - a, ac = c - a;
  // Degenerate (collinear, or with coincident corners) triangles first: the region tests below
  // assume a proper triangle (with a == b they take edge AB with a zero denominator and return
  // a; on a triangle collinear up to rounding their signs and the face's barycentric
  // denominator are rounding noise, which placed the point far off the segment).
  if (!(ab.cross(ac).squaredNorm() > kFlat * ab.squaredNorm() * ac.squaredNorm()))
    return closest_point_on_edges(p, a, b, c);
  const Eigen::Vector3d ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;  // vertex region A

  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;  // vertex region B

  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {  // edge region AB
    const double denom = d1 - d3;
    return denom > 0 ? Eigen::Vector3d(a + (d1 / denom) * ab) : a;
  }

  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;  // vertex region C

  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {  // edge region AC
    const double denom = d2 - d6;
    return denom > 0 ? Eigen::Vector3d(a + (d2 / denom) * ac) : a;
  }

  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {  // edge region BC
    const double denom = (d4 - d3) + (d5 - d6);
    return denom > 0 ? Eigen::Vector3d(b + ((d4 - d3) / denom) * (c - b)) : b;
  }

  // Face region. sum = |ab×ac|² up to rounding, so positive here; the check is a guard (a p that
  // is not finite, or so far away that rounding swamps sum).
  const double sum = va + vb + vc;
  if (!(sum > 0)) return closest_point_on_edges(p, a, b, c);
  const double v = vb / sum, w = vc / sum;
  return a + v * ab + w * ac;
}

namespace {
constexpr int kLeafSize = 4;

/// Squared distance from p to the box [lo, hi] (0 inside): a lower bound for every triangle in it.
double box_squared_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& lo,
                            const Eigen::Vector3d& hi) {
  const Eigen::Vector3d d = (lo - p).cwiseMax(p - hi).cwiseMax(0.0);
  return d.squaredNorm();
}
}  // namespace

TriangleBvh::TriangleBvh(const Positions& vertices, const Triangles& faces) {
  const int m = int(faces.rows());
  if (m > 0 && (faces.minCoeff() < 0 || faces.maxCoeff() >= vertices.rows()))
    throw std::invalid_argument("TriangleBvh: a face refers to a vertex that does not exist");
  std::vector<Eigen::Vector3d> centroids(m);
  for (int f = 0; f < m; ++f)
    centroids[f] =
        (vertices.row(faces(f, 0)) + vertices.row(faces(f, 1)) + vertices.row(faces(f, 2)))
            .transpose() /
        3.0;
  order_.resize(m);
  std::iota(order_.begin(), order_.end(), 0);
  nodes_.reserve(m > 0 ? 2 * (m / kLeafSize + 1) : 0);
  if (m > 0) build(0, m, 1, vertices, faces, centroids);
  corners_.resize(3 * std::size_t(m));
  for (int s = 0; s < m; ++s)
    for (int k = 0; k < 3; ++k)
      corners_[3 * std::size_t(s) + k] = vertices.row(faces(order_[s], k)).transpose();
}

int TriangleBvh::build(int begin, int end, int depth, const Positions& vertices,
                       const Triangles& faces, const std::vector<Eigen::Vector3d>& centroids) {
  depth_ = std::max(depth_, depth);
  const int index = int(nodes_.size());
  nodes_.emplace_back();
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  Eigen::Vector3d clo = lo, chi = hi;
  for (int s = begin; s < end; ++s) {
    const int f = order_[s];
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d v = vertices.row(faces(f, k)).transpose();
      lo = lo.cwiseMin(v);
      hi = hi.cwiseMax(v);
    }
    clo = clo.cwiseMin(centroids[f]);
    chi = chi.cwiseMax(centroids[f]);
  }
  nodes_[index].lo = lo;
  nodes_[index].hi = hi;
  if (end - begin <= kLeafSize) {
    nodes_[index].first = begin;
    nodes_[index].count = end - begin;
    return index;
  }
  // Median split on the longest centroid axis: balanced (depth log2(n/4)) whatever the layout,
  // which bounds both the build cost and the traversal stack. Ties broken by index so the tree
  // does not depend on the standard library's nth_element.
  int axis;
  (chi - clo).maxCoeff(&axis);
  const int mid = begin + (end - begin) / 2;
  std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                   [&](int x, int y) {
                     const double cx = centroids[x][axis], cy = centroids[y][axis];
                     return cx < cy || (cx == cy && x < y);
                   });
  build(begin, mid, depth + 1, vertices, faces, centroids);  // left child = index + 1
  const int right = build(mid, end, depth + 1, vertices, faces, centroids);
  nodes_[index].first = right;
  nodes_[index].count = 0;
  return index;
}

void TriangleBvh::test_triangle(int slot, const Eigen::Vector3d& p, ClosestHit& best) const {
  const Eigen::Vector3d* c = &corners_[3 * std::size_t(slot)];
  const Eigen::Vector3d q = closest_point_on_triangle(p, c[0], c[1], c[2]);
  const double d2 = (q - p).squaredNorm();
  if (d2 < best.squared_distance) {
    best.squared_distance = d2;
    best.point = q;
    best.triangle = order_[slot];
  }
}

ClosestHit TriangleBvh::closest(const Eigen::Vector3d& p, double bound_squared) const {
  ClosestHit best;
  best.squared_distance = bound_squared;
  if (nodes_.empty()) return best;
  // Iterative depth-first traversal, nearer child first, pruning boxes no nearer than the best
  // so far. The tree is balanced, so a small fixed stack suffices (depth ≤ ~40 for 2^40 faces).
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const int n = stack[--top];
    const Node& node = nodes_[n];
    if (box_squared_distance(p, node.lo, node.hi) >= best.squared_distance) continue;
    if (node.count > 0) {
      for (int s = node.first; s < node.first + node.count; ++s) test_triangle(s, p, best);
      continue;
    }
    const int left = n + 1, right = node.first;
    const double dl = box_squared_distance(p, nodes_[left].lo, nodes_[left].hi);
    const double dr = box_squared_distance(p, nodes_[right].lo, nodes_[right].hi);
    // Push the farther child first so the nearer one is popped next and tightens the bound.
    if (dl <= dr) {
      stack[top++] = right;
      stack[top++] = left;
    } else {
      stack[top++] = left;
      stack[top++] = right;
    }
  }
  return best;
}

ClosestHit TriangleBvh::closest_brute_force(const Eigen::Vector3d& p) const {
  ClosestHit best;
  for (int s = 0; s < int(order_.size()); ++s) test_triangle(s, p, best);
  return best;
}

}  // namespace mcf
