#include "bases/tracked_octree_basis.h"

#include "bases/cell_blocks.h"
#include "core/parallel.h"
#include "core/vec4.h"

#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

namespace mcf {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// A metric whose determinant falls this low is a pinch: the triangle has collapsed (area ratio
// below 1e-12 of X_0's, where g = I) or flattened to a segment (the two tangent vectors parallel
// to rounding: det below 1e-12 of g11·g22). The paper lets such points contribute nothing.
constexpr double kDegenerateDeterminant = 1e-24;
constexpr double kDegenerateRelative = 1e-12;

}  // namespace

TrackedOctreeBasis::TrackedOctreeBasis(const TriangleMesh& mesh, OctreeOptions options)
    : initial_(std::make_unique<RebuiltOctreeBasis>(mesh, options)),
      rule_(&cubature_rule(options.cubature)) {
  const auto t0 = Clock::now();
  const Octree& octree = initial_->octree();
  const OctreeLevel& L = octree.finest();
  const GridCube& cube = octree.cube;
  const double h = cube.cell_size(L.depth), inv_h = 1.0 / h;
  const OctreeSystem& system = initial_->system();
  const auto& pieces = initial_->pieces();
  const auto& order = system.piece_order();

  // Pieces in cell order, corners in their cell's local coordinates (p - cell origin) / h, stored
  // as fans (see the header): two passes over the cells, one to find the continuations and count
  // each cell's points, one to write them.
  const std::size_t nc = L.cells.size();
  const auto local_corners = [&](std::size_t c, int s, double q[9]) {
    const auto ijk = grid_index(L.cells[c]);
    const ClippedTriangle& t = pieces[static_cast<std::size_t>(order[static_cast<std::size_t>(s)])];
    for (int v = 0; v < 3; ++v)
      for (int a = 0; a < 3; ++a)
        q[3 * v + a] = (t.corners[v][a] - cube.origin[a]) * inv_h - ijk[a];
  };
  continues_.assign(order.size(), 0);
  point_start_.assign(nc + 1, 0);
  parallel_for_indices<std::size_t>(nc, 256, [&](std::size_t c) {
    double prev[9], q[9];
    int points = 0;
    for (int s = cell_start()[c]; s < cell_start()[c + 1]; ++s) {
      local_corners(c, s, q);
      const bool fan = s > cell_start()[c] && std::memcmp(q, prev, 3 * sizeof(double)) == 0 &&
                       std::memcmp(q + 3, prev + 6, 3 * sizeof(double)) == 0;
      continues_[std::size_t(s)] = fan;
      points += fan ? 1 : 3;
      std::memcpy(prev, q, sizeof(q));
    }
    point_start_[c + 1] = points;
  });
  for (std::size_t c = 0; c < nc; ++c) point_start_[c + 1] += point_start_[c];
  // One double of padding: the last corner is read as four doubles.
  fan_points_.assign(3 * std::size_t(point_start_[nc]) + 1, 0.0);
  parallel_for_indices<std::size_t>(nc, 256, [&](std::size_t c) {
    double* out = &fan_points_[3 * std::size_t(point_start_[c])];
    double q[9];
    for (int s = cell_start()[c]; s < cell_start()[c + 1]; ++s) {
      local_corners(c, s, q);
      const int skip = continues_[std::size_t(s)] ? 6 : 0;
      out = std::copy(q + skip, q + 9, out);
    }
  });
  // Only the original vertices are evaluated (with refine_input the midpoints are internal).
  stencils_ = vertex_stencils(octree, mesh.vertices, mesh.faces);
  // From here on only the compact corners are read: the rebuilt basis's pieces are freed and its
  // assembled matrices become ours, so the first update only resets their values (a fresh copy of
  // the pattern cost more than the update itself in page faults).
  initial_->release_assembly(mass_, stiffness_, normal_gradient_);
  const double preprocess = seconds_since(t0);

  const auto t1 = Clock::now();
  update(initial_coefficients(), true, true);
  const double integrate = seconds_since(t1);

  stats_ = initial_->stats();
  stats_.setup_seconds["integrate_initial"] = stats_.setup_seconds["integrate"];
  stats_.setup_seconds["preprocess"] = preprocess;
  stats_.setup_seconds["integrate"] = integrate;
  stats_.bytes_per_cubature_point = double(preprocessed_bytes()) / double(stats_.cubature_points);
}

std::size_t TrackedOctreeBasis::preprocessed_bytes() const {
  return fan_points_.size() * sizeof(double) + continues_.size() * sizeof(std::uint8_t) +
         (cell_start().size() + point_start_.size()) * sizeof(int);
}

long long TrackedOctreeBasis::fan_continuations() const {
  return std::count(continues_.begin(), continues_.end(), std::uint8_t(1));
}

namespace {

using namespace vec4;  // one cubature point per lane

/// Cubature points of one cell staged one array per quantity, so that ComputeDifferential (the
/// metric, √|g| and g⁻¹ at every point) runs four points per instruction: scalar, this was ~60%
/// of the update's time (the sqrt and the division alone ~13%).
struct StagedPoints {
  static constexpr int kCapacity = 32;  // a multiple of 4
  alignas(32) double t[3][kCapacity], f1[3][kCapacity], f2[3][kCapacity], w[kCapacity];
  alignas(32) double wm[kCapacity], s11[kCapacity], s12[kCapacity], s22[kCapacity];
  alignas(32) long long ok[kCapacity];
  int n = 0;
};

/// ComputeDifferential for the staged points: dX = D (f1, f2) with D = ∂X/∂t, the Jacobian of the
/// trilinear map (its edge differences `edge`), g = dXᵀdX in the frame of X_0 (identity at t = 0),
/// w_m = w √|g| and S = w √|g| g⁻¹ = (w_m / det) [g22, -g12; -g12, g11]. A metric whose
/// determinant is not above both thresholds (or is not finite) marks its point degenerate.
inline void staged_metric(StagedPoints& P, const double (&edge)[3][4][3]) {
  for (int i0 = 0; i0 < P.n; i0 += 4) {
    const v4 t[3] = {load4(&P.t[0][i0]), load4(&P.t[1][i0]), load4(&P.t[2][i0])};
    const v4 f1[3] = {load4(&P.f1[0][i0]), load4(&P.f1[1][i0]), load4(&P.f1[2][i0])};
    const v4 f2[3] = {load4(&P.f2[0][i0]), load4(&P.f2[1][i0]), load4(&P.f2[2][i0])};
    v4 ju[3] = {}, jv[3] = {};
    for (int a = 0; a < 3; ++a) {
      // ∂X/∂t_a is the bilinear interpolation of the 4 edge differences along a.
      const v4 s1 = t[(a + 1) % 3], s2 = t[(a + 2) % 3];
      const v4 one = splat(1.0);
      const v4 w0 = (one - s1) * (one - s2), w1 = s1 * (one - s2), w2 = (one - s1) * s2,
               w3 = s1 * s2;
      for (int d = 0; d < 3; ++d) {
        const v4 D = w0 * splat(edge[a][0][d]) + w1 * splat(edge[a][1][d]) +
                     w2 * splat(edge[a][2][d]) + w3 * splat(edge[a][3][d]);
        ju[d] += D * f1[a];
        jv[d] += D * f2[a];
      }
    }
    const v4 g11 = ju[0] * ju[0] + ju[1] * ju[1] + ju[2] * ju[2];
    const v4 g12 = ju[0] * jv[0] + ju[1] * jv[1] + ju[2] * jv[2];
    const v4 g22 = jv[0] * jv[0] + jv[1] * jv[1] + jv[2] * jv[2];
    const v4 det = g11 * g22 - g12 * g12;
    const m4 ok = (det > splat(kDegenerateDeterminant)) &
                  (det > splat(kDegenerateRelative) * g11 * g22) &
                  (det < splat(std::numeric_limits<double>::infinity()));
    const v4 safe = ok ? det : splat(1.0);
    const v4 wm = load4(&P.w[i0]) * sqrt4(safe);
    const v4 sc = wm / safe;
    store4(&P.wm[i0], wm);
    store4(&P.s11[i0], sc * g22);
    store4(&P.s12[i0], -sc * g12);
    store4(&P.s22[i0], sc * g11);
    std::memcpy(&P.ok[i0], &ok, sizeof(ok));
  }
}

/// Walks one cell's pieces through its fans (see the header): p0, p1, p2 point at the current
/// piece's corners inside the cell's fan points.
struct FanCursor {
  const double* next;
  const double *p0 = nullptr, *p1 = nullptr, *p2 = nullptr;
  void advance(bool continues) {
    if (continues) {  // (p0, p_k, p_k+1) after (p0, p_k-1, p_k): one new corner
      p1 = p2;
      p2 = next;
      next += 3;
    } else {
      p0 = next;
      p1 = next + 3;
      p2 = next + 6;
      next += 9;
    }
  }
};

/// One cell of SetSystemMatrices at the coefficients xc of its 8 corners: every cubature point of
/// its pieces (corners in cell-local coordinates, stored as fans: `points`, `continues`) goes into
/// `blocks`. Returns the number of degenerate points, which contribute nothing.
template <class Blocks>
int integrate_cell(const double xc[8][3], const double* points, const std::uint8_t* continues,
                   int pieces, const CubatureRule& rule, double h, Blocks& blocks) {
  const double inv_h = 1.0 / h;
  // Edge differences of the trilinear map X(t) = Σ_c xc_c β_c(t) along each axis a, one per
  // cell edge: ∂X/∂t_a at t is their bilinear interpolation in the two other coordinates.
  double edge[3][4][3];
  for (int a = 0; a < 3; ++a) {
    const int b1 = (a + 1) % 3, b2 = (a + 2) % 3;
    for (int e = 0; e < 4; ++e) {
      const int lo = ((e & 1) << b1) | (((e >> 1) & 1) << b2);
      for (int d = 0; d < 3; ++d) edge[a][e][d] = xc[lo | (1 << a)][d] - xc[lo][d];
    }
  }
  int degenerate = 0;
  StagedPoints P;
  // Metric of the staged points, then their blocks in staging order (the points' order is that
  // of the scalar loop: pieces in cell order, the rule's points in order).
  const auto flush = [&] {
    const int n = P.n;
    for (int i = n; i < (n + 3) / 4 * 4; ++i) {  // pad the last group of 4 with a unit point
      for (int a = 0; a < 3; ++a) P.t[a][i] = 0.5, P.f1[a][i] = a == 0, P.f2[a][i] = a == 1;
      P.w[i] = 0.0;
    }
    P.n = (n + 3) / 4 * 4;
    staged_metric(P, edge);
    for (int i = 0; i < n; ++i) {
      if (!P.ok[i]) {
        ++degenerate;
        continue;
      }
      const double t[3] = {P.t[0][i], P.t[1][i], P.t[2][i]};
      const double f1[3] = {P.f1[0][i], P.f1[1][i], P.f1[2][i]};
      const double f2[3] = {P.f2[0][i], P.f2[1][i], P.f2[2][i]};
      blocks.add(t, f1, f2, P.wm[i], P.s11[i], P.s12[i], P.s22[i]);
    }
    P.n = 0;
  };
  const int nq = rule.size();
  FanCursor fan{points};
  for (int s = 0; s < pieces; ++s) {
    fan.advance(continues[s]);
    // Orthonormal frame (e1, e2) of the piece's plane on X_0 (ComputeDifferential), in cell
    // units; tangent derivatives in world units: ∂/∂e = (e / h) · ∇_t.
    double f1[3], f2[3];
    const double len = piece_frame(fan.p0, fan.p1, fan.p2, inv_h, f1, f2);
    if (!(len > 0.0)) continue;
    const double area = 0.5 * len * h * h;
    // The corners as vectors (x, y, z, next value), so a point is three vector multiply-adds
    // and a clamp (scalar, the coordinates' arithmetic was ~10% of the update's instructions).
    const v4 c0 = load4(fan.p0), c1 = load4(fan.p1), c2 = load4(fan.p2);
    for (int q = 0; q < nq; ++q) {
      if (P.n == StagedPoints::kCapacity) flush();
      const auto& bc = rule.points[std::size_t(q)];
      const int i = P.n++;
      const v4 t = clamp01(splat(bc[0]) * c0 + splat(bc[1]) * c1 + splat(bc[2]) * c2);
      for (int a = 0; a < 3; ++a) {
        P.t[a][i] = t[a];
        P.f1[a][i] = f1[a];
        P.f2[a][i] = f2[a];
      }
      P.w[i] = area * rule.weights[std::size_t(q)];
    }
  }
  flush();
  blocks.finish();
  return degenerate;
}

/// The per-step update over all cells in tile order (OctreeSystem::tiles()): tiles of one colour
/// share no function, so the loop is lock-free and sums in the same order for any thread count.
template <bool Mass, bool Stiffness>
long long update_cells(const OctreeSystem& system, const OctreeLevel& L, const Coefficients& x,
                       const std::vector<double>& fan_points,
                       const std::vector<std::uint8_t>& continues,
                       const std::vector<int>& cell_start, const std::vector<int>& point_start,
                       const CubatureRule& rule, double h, double* Mv, double* Kv) {
  const double* X = x.data();
  const Eigen::Index ld = x.rows();  // column-major n x 3
  return system.for_each_tile([&](const int* cells, int n) {
    CellBlocks<Mass, Stiffness> blocks;
    long long degenerate = 0;
    for (int i = 0; i < n; ++i) {
      const int c = cells[i];
      const auto& f = L.cell_functions[std::size_t(c)];
      double xc[8][3];
      for (int a = 0; a < 8; ++a)
        for (int d = 0; d < 3; ++d) xc[a][d] = X[d * ld + f[std::size_t(a)]];
      blocks.clear();
      const int first = cell_start[std::size_t(c)];
      degenerate += integrate_cell(xc, &fan_points[3 * std::size_t(point_start[std::size_t(c)])],
                                   &continues[std::size_t(first)],
                                   cell_start[std::size_t(c) + 1] - first, rule, h, blocks);
      system.add_cell_blocks(c, blocks, Mass ? Mv : nullptr, Stiffness ? Kv : nullptr);
    }
    return degenerate;
  });
}

}  // namespace

void TrackedOctreeBasis::update(const Coefficients& x, bool update_mass, bool update_stiffness) {
  if (!update_mass && !update_stiffness) return;
  if (x.rows() != dimension())
    throw std::invalid_argument(
        "TrackedOctreeBasis::update: coefficient count does not match the dimension");
  const Octree& octree = initial_->octree();
  const OctreeLevel& L = octree.finest();
  const double h = octree.cube.cell_size(L.depth);
  const OctreeSystem& system = initial_->system();
  // The pattern never changes: only the values are reset (assign keeps the memory, so no
  // reallocation; the values live on the system's pattern, which both matrices share).
  const auto reset = [&system](std::vector<double>& values) {
    values.assign(std::size_t(system.non_zeros()), 0.0);
  };
  if (update_mass) reset(mass_);
  if (update_stiffness) reset(stiffness_);
  double* Mv = update_mass ? mass_.data() : nullptr;
  double* Kv = update_stiffness ? stiffness_.data() : nullptr;
  const auto run = [&](auto kernel) {
    return kernel(system, L, x, fan_points_, continues_, cell_start(), point_start_, *rule_, h, Mv,
                  Kv);
  };
  const long long degenerate = update_mass && update_stiffness ? run(update_cells<true, true>)
                               : update_mass                   ? run(update_cells<true, false>)
                                                               : run(update_cells<false, true>);
  degenerate_points_ = degenerate;
}

double TrackedOctreeBasis::max_metric_deviation(const Coefficients& x) const {
  const Octree& octree = initial_->octree();
  const OctreeLevel& L = octree.finest();
  const double inv_h = 1.0 / octree.cube.cell_size(L.depth);
  double worst = 0;
  for (std::size_t c = 0; c < L.cells.size(); ++c) {
    const auto& f = L.cell_functions[c];
    const std::vector<double> corners = cell_local_corners(int(c));
    for (int s = 0; s < cell_start()[c + 1] - cell_start()[c]; ++s) {
      const double* p = &corners[9 * std::size_t(s)];
      const Eigen::Vector3d p0(p[0], p[1], p[2]), p1(p[3], p[4], p[5]), p2(p[6], p[7], p[8]);
      const Eigen::Vector3d e1 = (p1 - p0).normalized();
      const Eigen::Vector3d e2 = (p1 - p0).cross(p2 - p0).normalized().cross(e1);
      for (int q = 0; q < rule_->size(); ++q) {
        const auto& b = rule_->points[std::size_t(q)];
        double t[3], val[8], grad[8][3];
        for (int a = 0; a < 3; ++a)
          t[a] = std::clamp(b[0] * p0[a] + b[1] * p1[a] + b[2] * p2[a], 0.0, 1.0);
        trilinear_values(t, inv_h, val, grad);
        Eigen::Matrix<double, 3, 2> J = Eigen::Matrix<double, 3, 2>::Zero();
        for (int a = 0; a < 8; ++a) {
          const Eigen::Vector3d g(grad[a][0], grad[a][1], grad[a][2]);
          J.col(0) += g.dot(e1) * x.row(f[std::size_t(a)]).transpose();
          J.col(1) += g.dot(e2) * x.row(f[std::size_t(a)]).transpose();
        }
        worst = std::max(worst,
                         ((J.transpose() * J) - Eigen::Matrix2d::Identity()).cwiseAbs().maxCoeff());
      }
    }
  }
  return worst;
}

std::vector<double> TrackedOctreeBasis::cell_local_corners(int c) const {
  const auto cell = static_cast<std::size_t>(c);
  std::vector<double> out;
  FanCursor fan{&fan_points_[3 * std::size_t(point_start_[cell])]};
  for (int s = cell_start()[cell]; s < cell_start()[cell + 1]; ++s) {
    fan.advance(continues_[std::size_t(s)]);
    for (const double* p : {fan.p0, fan.p1, fan.p2}) out.insert(out.end(), p, p + 3);
  }
  return out;
}

SparseView TrackedOctreeBasis::normal_gradient() const {
  if (normal_gradient_.empty()) return Basis::normal_gradient();
  return initial_->system().view(normal_gradient_);
}

Positions TrackedOctreeBasis::evaluate_vertices(const Coefficients& x) const {
  if (x.rows() != dimension())
    throw std::invalid_argument(
        "TrackedOctreeBasis::evaluate_vertices: coefficient count does not match the dimension");
  return mcf::evaluate_vertices(stencils_, x);
}

}  // namespace mcf
