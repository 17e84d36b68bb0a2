#include "harness/metrics.h"

#include "core/parallel.h"
#include "datasets/bvh.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace mcf {

namespace {

/// SplitMix64 finaliser: a counter-based generator, so sample i gets the same random numbers
/// whichever thread draws it and in whatever order (deterministic parallel sampling from a seed).
std::uint64_t mix(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

/// Uniform double in [0, 1) from 53 random bits: stream `k` of sample `i` under `seed`.
double uniform(std::uint64_t seed, std::uint64_t i, std::uint64_t k) {
  const std::uint64_t h = mix(mix(mix(seed) ^ i) ^ (k * 0xd1b54a32d192ed03ULL));
  return double(h >> 11) * 0x1.0p-53;
}

double triangle_area(const Positions& v, const Triangles& f, Eigen::Index t) {
  const Eigen::Vector3d a = v.row(f(t, 0)), b = v.row(f(t, 1)), c = v.row(f(t, 2));
  return 0.5 * (b - a).cross(c - a).norm();
}

void check_mesh(const TriangleMesh& m, const char* name) {
  if (m.num_faces() == 0)
    throw std::invalid_argument(std::string("mesh_distance: mesh ") + name + " has no faces");
  if (m.faces.minCoeff() < 0 || m.faces.maxCoeff() >= m.num_vertices())
    throw std::invalid_argument(std::string("mesh_distance: mesh ") + name +
                                " refers to a missing vertex");
}

/// Squared distances from `samples` points drawn uniformly by area on `from` to the surface `to`.
/// Uniform by area: pick a triangle with probability area/total (binary search in the prefix sums),
/// then a uniform point in it with the square-root warp (Osada et al. 2002).
std::vector<double> sampled_squared_distances(const TriangleMesh& from, const TriangleBvh& to,
                                              long long samples, std::uint64_t seed) {
  const Eigen::Index m = from.num_faces();
  std::vector<double> prefix(std::size_t(m) + 1, 0.0);
  for (Eigen::Index t = 0; t < m; ++t)
    prefix[t + 1] = prefix[t] + triangle_area(from.vertices, from.faces, t);
  const double total = prefix.back();
  if (!(total > 0) || !std::isfinite(total))
    throw std::invalid_argument("mesh_distance: a mesh has zero or non-finite area");

  std::vector<double> d2(std::size_t(samples), 0.0);
  parallel_for_indices<long long>(samples, 1024, [&](long long i) {
    const double u = uniform(seed, std::uint64_t(i), 0) * total;
    // First triangle whose prefix end exceeds u; zero-area triangles are never picked.
    auto it = std::upper_bound(prefix.begin() + 1, prefix.end(), u);
    Eigen::Index t = std::min<Eigen::Index>(Eigen::Index(it - prefix.begin()) - 1, m - 1);
    const double r1 = std::sqrt(uniform(seed, std::uint64_t(i), 1)),
                 r2 = uniform(seed, std::uint64_t(i), 2);
    const Eigen::Vector3d a = from.vertices.row(from.faces(t, 0)),
                          b = from.vertices.row(from.faces(t, 1)),
                          c = from.vertices.row(from.faces(t, 2));
    const Eigen::Vector3d p = (1 - r1) * a + r1 * (1 - r2) * b + r1 * r2 * c;
    d2[std::size_t(i)] = to.closest(p).squared_distance;
  });
  return d2;
}

struct Side {
  double sum_squares = 0, max = 0;
};

/// Serial, index-ordered sum: the result does not depend on how TBB split the work.
Side summarise(const std::vector<double>& d2) {
  Side s;
  for (const double x : d2) {
    s.sum_squares += x;
    s.max = std::max(s.max, x);
  }
  s.max = std::sqrt(s.max);
  return s;
}

}  // namespace

MeshDistance mesh_distance(const TriangleMesh& a, const TriangleMesh& b, long long samples,
                           std::uint64_t seed) {
  if (samples <= 0) throw std::invalid_argument("mesh_distance: samples must be positive");
  check_mesh(a, "A");
  check_mesh(b, "B");
  const TriangleBvh bvh_a(a.vertices, a.faces), bvh_b(b.vertices, b.faces);
  // Different streams for the two sides so that A == B does not give correlated sample sets.
  const Side fwd = summarise(sampled_squared_distances(a, bvh_b, samples, seed));
  const Side bwd =
      summarise(sampled_squared_distances(b, bvh_a, samples, mix(seed ^ 0x5bd1e995ULL)));
  MeshDistance d;
  d.samples = samples;
  d.rms_forward = std::sqrt(fwd.sum_squares / double(samples));
  d.max_forward = fwd.max;
  d.rms_backward = std::sqrt(bwd.sum_squares / double(samples));
  d.max_backward = bwd.max;
  d.rms = std::sqrt((fwd.sum_squares + bwd.sum_squares) / (2.0 * double(samples)));
  d.max = std::max(fwd.max, bwd.max);
  return d;
}

namespace {

/// The triangle's edge vectors b-a, c-a in an orthonormal frame of its own plane (columns).
/// Returns false for a degenerate triangle (no frame).
bool local_edges(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                 Eigen::Matrix2d& e) {
  const Eigen::Vector3d e1 = b - a, e2 = c - a;
  const Eigen::Vector3d n = e1.cross(e2);
  const double l1 = e1.norm(), ln = n.norm();
  if (!(l1 > 0) || !(ln > 0) || !std::isfinite(ln)) return false;
  const Eigen::Vector3d u = e1 / l1, v = n.cross(e1) / (ln * l1);  // v = n̂ × û, in-plane
  e << l1, e2.dot(u), 0.0, e2.dot(v);
  return true;
}

/// σ_max / σ_min of a 2×2 matrix by the closed form σ = (|z1| ± |z2|)/2 with
/// z1 = (a+d, c-b), z2 = (a-d, c+b): exact 1 for a similarity (z2 = 0) without any eigen-solver.
double singular_value_ratio(const Eigen::Matrix2d& j) {
  const double p = std::hypot(j(0, 0) + j(1, 1), j(1, 0) - j(0, 1));
  const double q = std::hypot(j(0, 0) - j(1, 1), j(1, 0) + j(0, 1));
  const double smax = 0.5 * (p + q), smin = 0.5 * std::abs(p - q);
  return smax / smin;  // inf (or nan for a zero map) when the current triangle is degenerate
}

}  // namespace

double quasi_conformal_error(const TriangleMesh& initial, const Positions& current) {
  if (current.rows() != initial.num_vertices())
    throw std::invalid_argument("quasi_conformal_error: current and initial vertex counts differ");
  const Positions& x0 = initial.vertices;
  const Triangles& f = initial.faces;
  // Per triangle: J = E_current · E_initial⁻¹ maps the initial triangle's local coordinates to the
  // current one's. Triangles degenerate now (pinched) have σ_min = 0 and an infinite ratio: they
  // are skipped (their initial area leaves the weights too), so the mean reports the distortion of
  // the triangles that still exist; a flow that degenerates is flagged by its stop reason instead.
  double weighted = 0, weights = 0;
  for (Eigen::Index t = 0; t < f.rows(); ++t) {
    Eigen::Matrix2d e0, e1;
    if (!local_edges(x0.row(f(t, 0)), x0.row(f(t, 1)), x0.row(f(t, 2)), e0))
      continue;  // no initial area
    if (!local_edges(current.row(f(t, 0)), current.row(f(t, 1)), current.row(f(t, 2)), e1))
      continue;
    const double ratio = singular_value_ratio(e1 * e0.inverse());
    if (!std::isfinite(ratio)) continue;
    const double w = 0.5 * std::abs(e0(0, 0) * e0(1, 1));
    weighted += w * ratio;
    weights += w;
  }
  return weights > 0 ? weighted / weights : std::numeric_limits<double>::quiet_NaN();
}

double sphericity(const Positions& vertices, const Triangles& faces) {
  const Eigen::Index n = vertices.rows();
  Eigen::VectorXd w = Eigen::VectorXd::Zero(n);
  for (Eigen::Index t = 0; t < faces.rows(); ++t) {
    const double a3 = triangle_area(vertices, faces, t) / 3.0;
    for (int k = 0; k < 3; ++k) w[faces(t, k)] += a3;
  }
  const double total = w.sum();
  if (!(total > 0)) return std::numeric_limits<double>::quiet_NaN();
  const Eigen::Vector3d centre = (vertices.transpose() * w) / total;
  const Eigen::VectorXd d = (vertices.rowwise() - centre.transpose()).rowwise().norm();
  const double mean = w.dot(d) / total;
  // Two-pass variance (deviations from the mean), not E[d²]−E[d]², which cancels catastrophically
  // for nearly spherical shapes — exactly the regime cMCF converges to.
  const double var = w.dot((d.array() - mean).square().matrix()) / total;
  return std::sqrt(var) / mean;
}

}  // namespace mcf
