#include "bases/tracked_octree_basis.h"

#include "bases/cell_blocks.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <chrono>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace mcf {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// A metric whose determinant falls this low is a pinch: the triangle has collapsed (area ratio
// below 1e-12 of X_0's, where g = I) or flattened to a segment (the two tangent vectors parallel
// to rounding: det below 1e-12 of g11·g22). The paper lets such points contribute nothing.
constexpr double kDegenerateDeterminant = 1e-24;
constexpr double kDegenerateRelative = 1e-12;

}  // namespace

TrackedOctreeBasis::TrackedOctreeBasis(const TriangleMesh& mesh, OctreeOptions options)
    : initial_(std::make_unique<RebuiltOctreeBasis>(mesh, options)), rule_(&cubature_rule(options.cubature)) {
  const auto t0 = Clock::now();
  const Octree& octree = initial_->octree();
  const OctreeLevel& L = octree.finest();
  const GridCube& cube = octree.cube;
  const double h = cube.cell_size(L.depth), inv_h = 1.0 / h;
  const OctreeSystem& system = initial_->system();
  const auto& pieces = initial_->pieces();
  const auto& order = system.piece_order();
  cell_start_ = system.cell_start();
  identity_ = initial_->initial_coefficients();

  // Pieces in cell order, corners in their cell's local coordinates (p - cell origin) / h.
  local_corners_.resize(9 * order.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, L.cells.size(), 256), [&](const auto& r) {
    for (std::size_t c = r.begin(); c != r.end(); ++c) {
      const auto ijk = grid_index(L.cells[c]);
      for (int s = cell_start_[c]; s < cell_start_[c + 1]; ++s) {
        const ClippedTriangle& t = pieces[static_cast<std::size_t>(order[static_cast<std::size_t>(s)])];
        for (int v = 0; v < 3; ++v)
          for (int a = 0; a < 3; ++a)
            local_corners_[9 * std::size_t(s) + 3 * v + a] = (t.corners[v][a] - cube.origin[a]) * inv_h - ijk[a];
      }
    }
  });
  // Only the original vertices are evaluated (with refine_input the midpoints are internal).
  stencils_ = point_stencils(octree, mesh.vertices);
  const double preprocess = seconds_since(t0);

  const auto t1 = Clock::now();
  update(identity_, true, true);
  const double integrate = seconds_since(t1);

  stats_ = initial_->stats();
  stats_.setup_seconds["integrate_initial"] = stats_.setup_seconds["integrate"];
  stats_.setup_seconds["preprocess"] = preprocess;
  stats_.setup_seconds["integrate"] = integrate;
  stats_.bytes_per_cubature_point = double(preprocessed_bytes()) / double(stats_.cubature_points);
}

std::size_t TrackedOctreeBasis::preprocessed_bytes() const {
  return local_corners_.size() * sizeof(double) + cell_start_.size() * sizeof(int);
}

namespace {

/// One cell of SetSystemMatrices at the coefficients xc of its 8 corners: every cubature point of
/// its pieces (corners in cell-local coordinates) goes into `blocks`. Returns the number of
/// degenerate points, which contribute nothing.
template <class Blocks>
int integrate_cell(const double xc[8][3], const double* corners, int pieces, const CubatureRule& rule, double h,
                   Blocks& blocks) {
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
  const int nq = rule.size();
  for (int s = 0; s < pieces; ++s) {
    const double* p = corners + 9 * s;
    // Orthonormal frame (e1, e2) of the piece's plane on X_0 (ComputeDifferential), in cell
    // units; tangent derivatives in world units: ∂/∂e = (e / h) · ∇_t.
    double f1[3], f2[3];
    const double len = piece_frame(p, p + 3, p + 6, inv_h, f1, f2);
    if (!(len > 0.0)) continue;
    const double area = 0.5 * len * h * h;
    for (int q = 0; q < nq; ++q) {
      const auto& bc = rule.points[std::size_t(q)];
      double t[3];
      for (int a = 0; a < 3; ++a) t[a] = std::clamp(bc[0] * p[a] + bc[1] * p[3 + a] + bc[2] * p[6 + a], 0.0, 1.0);
      // dX = D (f1, f2) with D = ∂X/∂t, the Jacobian of the trilinear map (3x3).
      double D[3][3];
      for (int a = 0; a < 3; ++a) {
        const double s1 = t[(a + 1) % 3], s2 = t[(a + 2) % 3];
        const double w[4] = {(1 - s1) * (1 - s2), s1 * (1 - s2), (1 - s1) * s2, s1 * s2};
        for (int d = 0; d < 3; ++d)
          D[d][a] = w[0] * edge[a][0][d] + w[1] * edge[a][1][d] + w[2] * edge[a][2][d] + w[3] * edge[a][3][d];
      }
      double Ju[3], Jv[3];
      for (int d = 0; d < 3; ++d) {
        Ju[d] = D[d][0] * f1[0] + D[d][1] * f1[1] + D[d][2] * f1[2];
        Jv[d] = D[d][0] * f2[0] + D[d][1] * f2[1] + D[d][2] * f2[2];
      }
      // Metric g = dXᵀdX in the frame of X_0 (identity at t = 0).
      const double g11 = Ju[0] * Ju[0] + Ju[1] * Ju[1] + Ju[2] * Ju[2];
      const double g12 = Ju[0] * Jv[0] + Ju[1] * Jv[1] + Ju[2] * Jv[2];
      const double g22 = Jv[0] * Jv[0] + Jv[1] * Jv[1] + Jv[2] * Jv[2];
      const double det = g11 * g22 - g12 * g12;
      if (!(det > kDegenerateDeterminant) || !(det > kDegenerateRelative * g11 * g22) || !std::isfinite(det)) {
        ++degenerate;
        continue;
      }
      // M: w √|g|;  K: w √|g| g⁻¹ = (w √|g| / det) [g22, -g12; -g12, g11].
      const double wm = area * rule.weights[std::size_t(q)] * std::sqrt(det);
      const double sc = wm / det;
      blocks.add(t, f1, f2, wm, sc * g22, -sc * g12, sc * g11);
    }
  }
  blocks.finish();
  return degenerate;
}

/// The per-step update over all cells in tile order (OctreeSystem::tiles()): tiles of one colour
/// share no function, so the loop is lock-free and sums in the same order for any thread count.
template <bool Mass, bool Stiffness>
long long update_cells(const OctreeSystem& system, const OctreeLevel& L, const Coefficients& x,
                       const std::vector<double>& local_corners, const std::vector<int>& cell_start,
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
      degenerate += integrate_cell(xc, &local_corners[9 * std::size_t(first)], cell_start[std::size_t(c) + 1] - first,
                                   rule, h, blocks);
      system.add_cell_blocks(c, blocks, Mass ? Mv : nullptr, Stiffness ? Kv : nullptr);
    }
    return degenerate;
  });
}

}  // namespace

void TrackedOctreeBasis::update(const Coefficients& x, bool update_mass, bool update_stiffness) {
  if (!update_mass && !update_stiffness) return;
  if (x.rows() != dimension())
    throw std::invalid_argument("TrackedOctreeBasis::update: coefficient count does not match the dimension");
  const Octree& octree = initial_->octree();
  const OctreeLevel& L = octree.finest();
  const double h = octree.cube.cell_size(L.depth);
  const OctreeSystem& system = initial_->system();
  // The pattern never changes: after the first update only the values are reset (no reallocation
  // and copy of the pattern every step, ~12 bytes per nonzero per matrix).
  auto reset = [&system](SparseMatrix& A) {
    if (A.isCompressed() && A.rows() == system.dimension() && A.nonZeros() == system.non_zeros())
      std::fill(A.valuePtr(), A.valuePtr() + A.nonZeros(), 0.0);
    else
      A = system.pattern();
  };
  if (update_mass) reset(mass_);
  if (update_stiffness) reset(stiffness_);
  double* Mv = update_mass ? mass_.valuePtr() : nullptr;
  double* Kv = update_stiffness ? stiffness_.valuePtr() : nullptr;
  const auto& corners = local_corners_;
  const long long degenerate =
      update_mass && update_stiffness
          ? update_cells<true, true>(system, L, x, corners, cell_start_, *rule_, h, Mv, Kv)
      : update_mass ? update_cells<true, false>(system, L, x, corners, cell_start_, *rule_, h, Mv, Kv)
                    : update_cells<false, true>(system, L, x, corners, cell_start_, *rule_, h, Mv, Kv);
  degenerate_points_ = degenerate;
}

double TrackedOctreeBasis::max_metric_deviation(const Coefficients& x) const {
  const Octree& octree = initial_->octree();
  const OctreeLevel& L = octree.finest();
  const double inv_h = 1.0 / octree.cube.cell_size(L.depth);
  double worst = 0;
  for (std::size_t c = 0; c < L.cells.size(); ++c) {
    const auto& f = L.cell_functions[c];
    for (int s = cell_start_[c]; s < cell_start_[c + 1]; ++s) {
      const double* p = &local_corners_[9 * std::size_t(s)];
      const Eigen::Vector3d p0(p[0], p[1], p[2]), p1(p[3], p[4], p[5]), p2(p[6], p[7], p[8]);
      const Eigen::Vector3d e1 = (p1 - p0).normalized();
      const Eigen::Vector3d e2 = (p1 - p0).cross(p2 - p0).normalized().cross(e1);
      for (int q = 0; q < rule_->size(); ++q) {
        const auto& b = rule_->points[std::size_t(q)];
        double t[3], val[8], grad[8][3];
        for (int a = 0; a < 3; ++a) t[a] = std::clamp(b[0] * p0[a] + b[1] * p1[a] + b[2] * p2[a], 0.0, 1.0);
        trilinear_values(t, inv_h, val, grad);
        Eigen::Matrix<double, 3, 2> J = Eigen::Matrix<double, 3, 2>::Zero();
        for (int a = 0; a < 8; ++a) {
          const Eigen::Vector3d g(grad[a][0], grad[a][1], grad[a][2]);
          J.col(0) += g.dot(e1) * x.row(f[std::size_t(a)]).transpose();
          J.col(1) += g.dot(e2) * x.row(f[std::size_t(a)]).transpose();
        }
        worst = std::max(worst, ((J.transpose() * J) - Eigen::Matrix2d::Identity()).cwiseAbs().maxCoeff());
      }
    }
  }
  return worst;
}

Positions TrackedOctreeBasis::evaluate_vertices(const Coefficients& x) const {
  if (x.rows() != dimension())
    throw std::invalid_argument("TrackedOctreeBasis::evaluate_vertices: coefficient count does not match the dimension");
  return evaluate_stencils(stencils_, x);
}

}  // namespace mcf
