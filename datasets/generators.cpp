// Analytic test shapes. Every closed shape is built without duplicate vertices at seams or
// poles (indices wrap around), so it is watertight; faces are counter-clockwise seen from
// outside (away from the axis for the open surfaces of revolution).

#include "datasets/generators.h"

#include "datasets/mesh_error.h"
#include "datasets/subdivide.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <string>
#include <tuple>
#include <vector>

namespace mcf {
namespace {

constexpr double kPi = std::numbers::pi;

void require(bool ok, const std::string& what) {
  if (!ok) throw MeshError("generator: " + what);
}

TriangleMesh icosahedron() {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  TriangleMesh m;
  m.vertices.resize(12, 3);
  m.vertices << -1, t, 0, 1, t, 0, -1, -t, 0, 1, -t, 0,  //
      0, -1, t, 0, 1, t, 0, -1, -t, 0, 1, -t,            //
      t, 0, -1, t, 0, 1, -t, 0, -1, -t, 0, 1;
  m.faces.resize(20, 3);
  m.faces << 0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11,  //
      1, 5, 9, 5, 11, 4, 11, 10, 2, 10, 7, 6, 7, 1, 8,         //
      3, 9, 4, 3, 4, 2, 3, 2, 6, 3, 6, 8, 3, 8, 9,             //
      4, 9, 5, 2, 4, 11, 6, 2, 10, 8, 6, 7, 9, 8, 1;
  m.vertices.rowwise().normalize();
  // Orientation guard: a convex body centred at the origin has outward normals along the
  // centroid direction. Cheap, and it keeps the table above honest.
  for (Eigen::Index f = 0; f < 20; ++f) {
    const Eigen::Vector3d a = m.vertices.row(m.faces(f, 0)), b = m.vertices.row(m.faces(f, 1)),
                          c = m.vertices.row(m.faces(f, 2));
    if ((b - a).cross(c - a).dot(a + b + c) < 0) std::swap(m.faces(f, 1), m.faces(f, 2));
  }
  return m;
}

// Grid of (nu [+1]) x (nv + 1) vertices, u wrapping around when `wrap_u`. Quads are split into
// (a, b, c), (a, c, d) with a=(i,j), b=(i+1,j), c=(i+1,j+1), d=(i,j+1): counter-clockwise when
// ∂p/∂u × ∂p/∂v points outward.
Triangles grid_faces(int nu, int nv, bool wrap_u) {
  const int cols = wrap_u ? nu : nu + 1;
  auto id = [&](int i, int j) { return j * cols + (wrap_u ? i % nu : i); };
  Triangles faces(2 * nu * nv, 3);
  int f = 0;
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const int a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
      faces.row(f++) << a, b, c;
      faces.row(f++) << a, c, d;
    }
  return faces;
}

// Surface of revolution about z of the profile (rho_k, z_k), k = 0..K, ordered bottom to top.
// When rho is 0 at an end, that end is a single pole vertex closing the surface there.
TriangleMesh revolve(const std::vector<double>& rho, const std::vector<double>& z, int n_around) {
  const int K = static_cast<int>(rho.size()) - 1;
  const bool bottom_pole = rho.front() == 0.0, top_pole = rho.back() == 0.0;
  const int first_ring = bottom_pole ? 1 : 0, last_ring = top_pole ? K - 1 : K;
  const int rings = last_ring - first_ring + 1;
  TriangleMesh m;
  m.vertices.resize(static_cast<Eigen::Index>(rings) * n_around + bottom_pole + top_pole, 3);
  for (int r = 0; r < rings; ++r)
    for (int i = 0; i < n_around; ++i) {
      const double th = 2 * kPi * i / n_around;
      const int k = first_ring + r;
      m.vertices.row(r * n_around + i) << rho[k] * std::cos(th), rho[k] * std::sin(th), z[k];
    }
  const Triangles band = grid_faces(n_around, rings - 1, true);
  std::vector<std::array<int, 3>> faces;
  faces.reserve(band.rows() + 2 * n_around);
  for (Eigen::Index f = 0; f < band.rows(); ++f)
    faces.push_back({band(f, 0), band(f, 1), band(f, 2)});
  int next = rings * n_around;
  if (bottom_pole) {
    const int p = next++;
    m.vertices.row(p) << 0, 0, z.front();
    for (int i = 0; i < n_around; ++i) faces.push_back({p, (i + 1) % n_around, i});
  }
  if (top_pole) {
    const int p = next++;
    m.vertices.row(p) << 0, 0, z.back();
    const int base = (rings - 1) * n_around;
    for (int i = 0; i < n_around; ++i) faces.push_back({base + i, base + (i + 1) % n_around, p});
  }
  m.faces.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (size_t f = 0; f < faces.size(); ++f) m.faces.row(f) << faces[f][0], faces[f][1], faces[f][2];
  return m;
}

// Closed surface of revolution (rho is 0 at both ends: two poles) with the vertex count of each
// ring proportional to its radius (at least 6, `max_around` at the widest ring), so triangles
// stay near-equilateral everywhere: a fixed count would leave slivers in the pole fans and
// crowd a thin neck. Neighbouring rings are stitched by a zipper that always advances on the
// ring whose next vertex comes first in angle; rings are staggered by half a step.
TriangleMesh revolve_closed(const std::vector<double>& rho, const std::vector<double>& z,
                            int max_around) {
  const int K = static_cast<int>(rho.size()) - 1;
  const double rho_max = *std::max_element(rho.begin(), rho.end());
  std::vector<int> count(K + 1, 1), start(K + 1, 0);
  std::vector<double> offset(K + 1, 0.0);
  int total = 0;
  for (int k = 0; k <= K; ++k) {
    if (k > 0 && k < K)
      count[k] = std::max(6, static_cast<int>(std::lround(max_around * rho[k] / rho_max)));
    offset[k] = (k % 2) * kPi / count[k];
    start[k] = total;
    total += count[k];
  }
  TriangleMesh m;
  m.vertices.resize(total, 3);
  for (int k = 0; k <= K; ++k)
    for (int i = 0; i < count[k]; ++i) {
      const double th = offset[k] + 2 * kPi * i / count[k];
      m.vertices.row(start[k] + i) << rho[k] * std::cos(th), rho[k] * std::sin(th), z[k];
    }
  m.vertices.row(0) << 0, 0, z.front();
  m.vertices.row(start[K]) << 0, 0, z.back();
  std::vector<std::array<int, 3>> faces;
  for (int k = 0; k < K; ++k) {
    const int nl = count[k], nu = count[k + 1];
    auto L = [&](int i) { return start[k] + i % nl; };
    auto U = [&](int u) { return start[k + 1] + u % nu; };
    if (nl == 1) {  // bottom pole fan
      for (int u = 0; u < nu; ++u) faces.push_back({L(0), U(u + 1), U(u)});
      continue;
    }
    if (nu == 1) {  // top pole fan
      for (int i = 0; i < nl; ++i) faces.push_back({L(i), L(i + 1), U(0)});
      continue;
    }
    auto angle_l = [&](int i) { return offset[k] + 2 * kPi * i / nl; };
    auto angle_u = [&](int u) { return offset[k + 1] + 2 * kPi * u / nu; };
    int i = 0, u = 0;
    while (i < nl || u < nu) {
      // (L_i, L_i+1, U_u) and (L_i, U_u+1, U_u) are the two halves of the outward grid quad.
      if (u == nu || (i < nl && angle_l(i + 1) < angle_u(u + 1))) {
        faces.push_back({L(i), L(i + 1), U(u)});
        ++i;
      } else {
        faces.push_back({L(i), U(u + 1), U(u)});
        ++u;
      }
    }
  }
  m.faces.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (size_t f = 0; f < faces.size(); ++f) m.faces.row(f) << faces[f][0], faces[f][1], faces[f][2];
  return m;
}

// Resamples a densely sampled profile curve at `segments` equal arc-length steps, so that
// rings are evenly spaced along the surface (no crowding at caps, no stretching at the neck).
void resample_by_arclength(const std::vector<double>& rho, const std::vector<double>& z,
                           int segments, std::vector<double>& out_rho, std::vector<double>& out_z) {
  std::vector<double> s(rho.size(), 0.0);
  for (size_t k = 1; k < rho.size(); ++k)
    s[k] = s[k - 1] + std::hypot(rho[k] - rho[k - 1], z[k] - z[k - 1]);
  out_rho.assign(segments + 1, 0.0);
  out_z.assign(segments + 1, 0.0);
  size_t k = 0;
  for (int j = 0; j <= segments; ++j) {
    const double target = s.back() * j / segments;
    while (k + 2 < s.size() && s[k + 1] < target) ++k;
    const double t =
        s[k + 1] > s[k] ? std::clamp((target - s[k]) / (s[k + 1] - s[k]), 0.0, 1.0) : 0.0;
    out_rho[j] = rho[k] + t * (rho[k + 1] - rho[k]);
    out_z[j] = z[k] + t * (z[k + 1] - z[k]);
  }
  // Poles must be exactly on the axis (revolve() recognises them by rho == 0).
  if (rho.front() == 0.0) out_rho.front() = 0.0;
  if (rho.back() == 0.0) out_rho.back() = 0.0;
}

double profile_length(const std::vector<double>& rho, const std::vector<double>& z) {
  double s = 0;
  for (size_t k = 1; k < rho.size(); ++k) s += std::hypot(rho[k] - rho[k - 1], z[k] - z[k - 1]);
  return s;
}

// Rows along the profile so that triangles are roughly equilateral at the widest ring.
int rows_for(double length, double max_rho, int n_around) {
  const double spacing = 2 * kPi * max_rho / n_around;
  return std::max(2, static_cast<int>(std::lround(length / spacing)));
}

}  // namespace

TriangleMesh make_icosphere(int level, double radius) {
  require(level >= 0 && level <= 12,
          "icosphere level must be in 0..12, got " + std::to_string(level));
  require(radius > 0, "icosphere radius must be positive");
  TriangleMesh m = icosahedron();
  // Project after every level (not once at the end): the classic icosphere, more uniform.
  for (int l = 0; l < level; ++l) {
    m = subdivide_midpoint(m);
    m.vertices.rowwise().normalize();
  }
  m.vertices *= radius;
  return m;
}

TriangleMesh make_sphere(long long target_vertices, double radius) {
  require(target_vertices >= 12,
          "sphere needs at least 12 vertices, got " + std::to_string(target_vertices));
  require(radius > 0, "sphere radius must be positive");
  // Frequency-k geodesic sphere: each icosahedron face carries a triangular grid with k segments
  // per edge, 10 k^2 + 2 vertices in all; k is the closest to the target.
  const int k = std::max(1, static_cast<int>(std::lround(std::sqrt((target_vertices - 2) / 10.0))));
  const TriangleMesh ico = icosahedron();
  std::vector<Eigen::RowVector3d> verts;
  verts.reserve(10ll * k * k + 2);
  for (int v = 0; v < 12; ++v) verts.push_back(ico.vertices.row(v));
  // Shared points are created once: edge points keyed by (low corner, high corner, steps from
  // the low corner); interior points belong to one face only.
  std::map<std::tuple<int, int, int>, int> edge_point;
  std::vector<std::array<int, 3>> faces;
  faces.reserve(20ll * k * k);
  std::vector<int> grid((k + 1) * (k + 1));
  for (Eigen::Index f = 0; f < 20; ++f) {
    const int c[3] = {ico.faces(f, 0), ico.faces(f, 1), ico.faces(f, 2)};
    for (int i = 0; i <= k; ++i)
      for (int j = 0; i + j <= k; ++j) {
        const int w[3] = {k - i - j, i, j};  // integer barycentric weights of c0, c1, c2
        int nonzero = 0, only = -1;
        for (int a = 0; a < 3; ++a)
          if (w[a] > 0) ++nonzero, only = a;
        int id;
        if (nonzero == 1) {
          id = c[only];
        } else if (nonzero == 2) {
          int p = -1, q = -1;
          for (int a = 0; a < 3; ++a)
            if (w[a] > 0) (p < 0 ? p : q) = a;
          int lo = p, hi = q;
          if (c[lo] > c[hi]) std::swap(lo, hi);
          auto key = std::make_tuple(c[lo], c[hi], w[hi]);
          auto it = edge_point.find(key);
          if (it == edge_point.end()) {
            it = edge_point.emplace(key, static_cast<int>(verts.size())).first;
            verts.push_back((w[0] * ico.vertices.row(c[0]) + w[1] * ico.vertices.row(c[1]) +
                             w[2] * ico.vertices.row(c[2])) /
                            k);
          }
          id = it->second;
        } else {
          id = static_cast<int>(verts.size());
          verts.push_back((w[0] * ico.vertices.row(c[0]) + w[1] * ico.vertices.row(c[1]) +
                           w[2] * ico.vertices.row(c[2])) /
                          k);
        }
        grid[i * (k + 1) + j] = id;
      }
    // Moving i goes toward c1 and j toward c2, so (i,j),(i+1,j),(i,j+1) has the face's orientation.
    auto g = [&](int i, int j) { return grid[i * (k + 1) + j]; };
    for (int i = 0; i < k; ++i)
      for (int j = 0; i + j < k; ++j) {
        faces.push_back({g(i, j), g(i + 1, j), g(i, j + 1)});
        if (i + j + 1 < k) faces.push_back({g(i + 1, j), g(i + 1, j + 1), g(i, j + 1)});
      }
  }
  TriangleMesh m;
  m.vertices.resize(static_cast<Eigen::Index>(verts.size()), 3);
  for (size_t v = 0; v < verts.size(); ++v) m.vertices.row(v) = radius * verts[v].normalized();
  m.faces.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (size_t f = 0; f < faces.size(); ++f) m.faces.row(f) << faces[f][0], faces[f][1], faces[f][2];
  return m;
}

TriangleMesh make_torus(double R, double r, int n_major, int n_minor) {
  require(R > r && r > 0, "torus needs R > r > 0");
  require(n_major >= 3 && n_minor >= 3, "torus needs n_major, n_minor >= 3");
  TriangleMesh m;
  m.vertices.resize(static_cast<Eigen::Index>(n_major) * n_minor, 3);
  for (int j = 0; j < n_minor; ++j)
    for (int i = 0; i < n_major; ++i) {
      const double u = 2 * kPi * i / n_major, v = 2 * kPi * j / n_minor;
      m.vertices.row(j * n_major + i) << (R + r * std::cos(v)) * std::cos(u),
          (R + r * std::cos(v)) * std::sin(u), r * std::sin(v);
    }
  // ∂p/∂u × ∂p/∂v is the outward normal for this parametrisation; v wraps as well, so the
  // last row of quads reuses row 0 (grid_faces wraps u only, hence the modulo below).
  m.faces = grid_faces(n_major, n_minor, true);
  const int nv = n_major * n_minor;
  for (Eigen::Index f = 0; f < m.faces.rows(); ++f)
    for (int c = 0; c < 3; ++c) m.faces(f, c) %= nv;
  return m;
}

TriangleMesh make_cubical_spiral(int turns, int segments_per_turn, int profile_segments) {
  require(turns >= 1, "spiral needs turns >= 1");
  require(segments_per_turn >= 4 && profile_segments >= 1,
          "spiral needs segments_per_turn >= 4 and profile_segments >= 1");
  // A vertical ribbon that winds around the z axis along a square (side 2) while rising one unit
  // per turn: the "cubical helix" stand-in for the paper's cubical spiral. The ribbon is 0.6
  // high, so consecutive turns stay 0.4 apart. Each side gets an equal share of the segments
  // (rounded up to a multiple of 4) so the corners are sharp vertices.
  const int per_side = (segments_per_turn + 3) / 4;
  const int nu = 4 * per_side * turns;
  const double height = 0.6, pitch = 1.0;
  const double corners[5][2] = {{1, -1}, {1, 1}, {-1, 1}, {-1, -1}, {1, -1}};  // counter-clockwise
  TriangleMesh m;
  m.vertices.resize(static_cast<Eigen::Index>(nu + 1) * (profile_segments + 1), 3);
  for (int j = 0; j <= profile_segments; ++j)
    for (int i = 0; i <= nu; ++i) {
      const int side = (i / per_side) % 4, step = i % per_side;
      const double t = static_cast<double>(step) / per_side;
      const double x = corners[side][0] + t * (corners[side + 1][0] - corners[side][0]);
      const double y = corners[side][1] + t * (corners[side + 1][1] - corners[side][1]);
      const double z = pitch * i / (4.0 * per_side) + height * j / profile_segments;
      m.vertices.row(j * (nu + 1) + i) << x, y, z;
    }
  // Tangent (counter-clockwise) × up points away from the axis: outward.
  m.faces = grid_faces(nu, profile_segments, false);
  return m;
}

TriangleMesh make_dumbbell(int resolution) {
  require(resolution >= 8, "dumbbell resolution must be >= 8");
  // Two unit spheres centred at z = ±c joined by a neck of radius `neck`. ρ² is a smooth
  // maximum (log-sum-exp) of the sphere profile and the neck's ρ² between the centres, so the
  // neck is thin but without creases; beyond the centres it is the plain sphere.
  const double c = 1.5, neck = 0.25, sharp = 20.0;
  auto rho2 = [&](double z) {
    const double az = std::abs(z);
    const double sphere = 1.0 - (az - c) * (az - c);
    if (az >= c) return std::max(0.0, sphere);
    const double hi = std::max(sphere, neck * neck), lo = std::min(sphere, neck * neck);
    return hi + std::log1p(std::exp(-sharp * (hi - lo))) / sharp;
  };
  const int dense = 20000;
  std::vector<double> rho(dense + 1), z(dense + 1);
  for (int k = 0; k <= dense; ++k) {
    // Cosine spacing samples the poles finely, where ρ(z) is steep.
    z[k] = -(c + 1) * std::cos(kPi * k / dense);
    rho[k] = std::sqrt(rho2(z[k]));
  }
  rho.front() = rho.back() = 0.0;
  std::vector<double> r2, z2;
  resample_by_arclength(rho, z, rows_for(profile_length(rho, z), 1.0, resolution), r2, z2);
  return revolve_closed(r2, z2, resolution);
}

TriangleMesh make_rounded_cylinder(double radius, double length, int resolution) {
  require(radius > 0 && length > 0, "rounded_cylinder needs radius > 0 and length > 0");
  require(resolution >= 3, "rounded_cylinder resolution must be >= 3");
  // Profile: quarter circle (bottom cap), straight side, quarter circle (top cap); the cylinder
  // part spans z in [-length/2, length/2].
  const int dense = 4000;
  std::vector<double> rho, z;
  for (int k = 0; k <= dense; ++k) {
    const double a = -kPi / 2 + (kPi / 2) * k / dense;
    rho.push_back(radius * std::cos(a));
    z.push_back(-length / 2 + radius * std::sin(a));
  }
  for (int k = 1; k <= dense; ++k) {
    const double a = (kPi / 2) * k / dense;
    rho.push_back(radius * std::cos(a));
    z.push_back(length / 2 + radius * std::sin(a));
  }
  rho.front() = rho.back() = 0.0;
  std::vector<double> r2, z2;
  resample_by_arclength(rho, z, rows_for(profile_length(rho, z), radius, resolution), r2, z2);
  return revolve_closed(r2, z2, resolution);
}

TriangleMesh make_open_cylinder(double radius, double length, int n_around, int n_along) {
  require(radius > 0 && length > 0, "open_cylinder needs radius > 0 and length > 0");
  require(n_around >= 3 && n_along >= 1, "open_cylinder needs n_around >= 3 and n_along >= 1");
  std::vector<double> rho(n_along + 1, radius), z(n_along + 1);
  for (int j = 0; j <= n_along; ++j) z[j] = -length / 2 + length * j / n_along;
  return revolve(rho, z, n_around);
}

TriangleMesh make_catenoid(double waist, double height, int n_around, int n_along) {
  require(waist > 0 && height > 0, "catenoid needs waist > 0 and height > 0");
  require(n_around >= 3 && n_along >= 1, "catenoid needs n_around >= 3 and n_along >= 1");
  // ρ(z) = waist · cosh(z / waist), the minimal surface of revolution.
  std::vector<double> rho(n_along + 1), z(n_along + 1);
  for (int j = 0; j <= n_along; ++j) {
    z[j] = -height + 2 * height * j / n_along;
    rho[j] = waist * std::cosh(z[j] / waist);
  }
  return revolve(rho, z, n_around);
}

}  // namespace mcf
