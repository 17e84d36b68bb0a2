#include "bases/hat_basis.h"

#include "bases/vertex_ordering.h"
#include "core/parallel.h"
#include "datasets/face_order.h"
#include "datasets/validate.h"

#include <Eigen/Geometry>

#include <chrono>
#include <span>
#include <utility>

namespace mcf {

namespace {

/// What one triangle contributes: its area and half the cotangent of the angle at each corner
/// (the weight of the edge opposite it in K).
struct FaceTerms {
  double area;
  double half_cot[3];
};

/// A triangle's FaceTerms. cot at p between edges to q and r = (e1·e2) / |e1×e2|, and |e1×e2| is
/// twice the area at every corner, so one cross product serves all three. A collapsed triangle
/// (pinching) contributes no weights rather than inf, so the flow can report the singularity.
inline FaceTerms face_terms(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                            const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, bc = c - b, ca = a - c;
  const double twice_area = ab.cross(-ca).norm();
  const double h = twice_area > 0.0 ? 0.5 / twice_area : 0.0;
  return {0.5 * twice_area, {-h * ab.dot(ca), -h * bc.dot(ab), -h * ca.dot(bc)}};
}

}  // namespace

HatBasis::HatBasis(const TriangleMesh& mesh, MassKind mass_kind,
                   std::optional<SurfaceHierarchyOptions> hierarchy, Eigen::Index output_vertices)
    : vertices0_(mesh.vertices),
      faces_(mesh.faces),
      output_vertices_(output_vertices < 0 ? mesh.num_vertices()
                                           : std::min(output_vertices, mesh.num_vertices())),
      mass_kind_(mass_kind) {
  const auto t0 = std::chrono::steady_clock::now();
  Triangles hierarchy_faces;
  if (hierarchy) {
    // Functions numbered so that neighbours are close (bases/vertex_ordering.h), which the
    // multigrid's parallel relaxation needs; the mesh's own order is restored on evaluation.
    order_ = bandwidth_ordering(faces_, int(vertices0_.rows()));
    std::vector<int> rank(order_.size());
    for (std::size_t k = 0; k < order_.size(); ++k) rank[std::size_t(order_[k])] = int(k);
    for (std::size_t k = 0; k < order_.size(); ++k)
      vertices0_.row(Eigen::Index(k)) = mesh.vertices.row(order_[k]);
    for (Eigen::Index f = 0; f < faces_.rows(); ++f)
      for (int c = 0; c < 3; ++c) faces_(f, c) = rank[std::size_t(faces_(f, c))];
    // The hierarchy is built on the faces in the mesh's order (below); the assembly reads them
    // sorted by their first function, so that the update's per-face pass reads neighbouring
    // corners and its gathers, per nonzero of a column, faces stored close together.
    hierarchy_faces = std::move(faces_);
    faces_ = faces_by_smallest_vertex(hierarchy_faces, vertices0_.rows());
  }
  const auto t0b = std::chrono::steady_clock::now();
  const Eigen::Index m = faces_.rows();
  std::vector<int> rows(9 * m), cols(9 * m);
  for (Eigen::Index f = 0; f < m; ++f)
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) {
        rows[9 * f + 3 * a + b] = faces_(f, a);
        cols[9 * f + 3 * a + b] = faces_(f, b);
      }
  pattern_ = FixedPattern(vertices0_.rows(), rows, cols);
  boundary_ = boundary_vertices(TriangleMesh{vertices0_, faces_});
  const auto t1 = std::chrono::steady_clock::now();
  update(vertices0_, true, true);
  const auto t2 = std::chrono::steady_clock::now();

  stats_.dimension = vertices0_.rows();
  stats_.split_triangles = m;
  stats_.cubature_points = 0;
  stats_.levels = 1;
  stats_.setup_seconds["pattern"] = std::chrono::duration<double>(t1 - t0b).count();
  stats_.setup_seconds["integrate"] = std::chrono::duration<double>(t2 - t1).count();
  if (hierarchy) {
    const auto t3 = std::chrono::steady_clock::now();
    hierarchy_ = build_surface_hierarchy(vertices0_, hierarchy_faces, *hierarchy);
    hierarchy_.points.clear();  // only the prolongations and colours are used by the solver
    hierarchy_.points.shrink_to_fit();
    stats_.levels = int(hierarchy_.colours.size());
    stats_.setup_seconds["hierarchy"] =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t3).count() +
        std::chrono::duration<double>(t0b - t0).count();
  }
}

Positions HatBasis::evaluate_vertices(const Coefficients& x) const {
  if (order_.empty())
    return output_vertices_ == x.rows() ? Positions(x) : x.topRows(output_vertices_);
  Positions V(output_vertices_, 3);
  parallel_for_indices<std::size_t>(order_.size(), 4096, [&](std::size_t k) {
    if (order_[k] < output_vertices_) V.row(order_[k]) = x.row(Eigen::Index(k));
  });
  return V;
}

void HatBasis::update(const Coefficients& x, bool update_mass, bool update_stiffness) {
  if (!update_mass && !update_stiffness) return;
  const Eigen::Index m = faces_.rows();
  // One pass over the faces writes what each face contributes, compactly: its area (the mass)
  // and half the cotangent at each corner (the stiffness); the gathers below then sum, per
  // nonzero, the values of the faces whose slots land on it (9 slots a face, slot 3a + b for
  // corners a, b). Reading one area per slot instead of a 3 x 3 block per face keeps the gather's
  // random reads within a ninth of the bytes (docs/benchmarks.md, "Floors").
  if (update_mass) face_area_.resize(std::size_t(m));
  if (update_stiffness) corner_weight_.resize(3 * std::size_t(m));
  // The coefficients row-major first (a streaming pass): each face then reads its three corners
  // as three 24-byte runs instead of nine scattered doubles of x's three columns.
  points_.resize(std::size_t(x.rows()));
  parallel_for_indices<Eigen::Index>(
      x.rows(), 4096, [&](Eigen::Index i) { points_[std::size_t(i)] = x.row(i).transpose(); });
  const auto corner = [&](Eigen::Index f, int c) -> const Eigen::Vector3d& {
    return points_[std::size_t(faces_(f, c))];
  };
  if (update_stiffness) {
    parallel_for_indices<Eigen::Index>(m, 2048, [&](Eigen::Index f) {
      const FaceTerms t = face_terms(corner(f, 0), corner(f, 1), corner(f, 2));
      if (update_mass) face_area_[std::size_t(f)] = t.area;
      for (int c = 0; c < 3; ++c)
        corner_weight_[3 * std::size_t(f) + std::size_t(c)] = t.half_cot[c];
    });
  } else {
    // The area alone: the inlined cotangents, unused, are left out by the compiler.
    parallel_for_indices<Eigen::Index>(m, 2048, [&](Eigen::Index f) {
      face_area_[std::size_t(f)] = face_terms(corner(f, 0), corner(f, 1), corner(f, 2)).area;
    });
  }
  // Consistent P1 mass: A/6 on the diagonal, A/12 off it; lumped: A/3 on the diagonal, 0 off it.
  // Stiffness off the diagonal: -Σ w over the faces sharing the edge (w of the corner opposite
  // it, the third corner 3 - a - b); on it, minus the column's off-diagonal sum (rows sum to
  // zero). Both are gathered in one pass over a column's slots when both change.
  const bool lumped = mass_kind_ == MassKind::lumped;
  const double diagonal_share = lumped ? 1.0 / 3.0 : 1.0 / 6.0;
  const double off_share = lumped ? 0.0 : 1.0 / 12.0;
  // Slots are non-negative: unsigned division by 9 is a multiply and a shift.
  const auto is_diagonal_slot = [](int slot) { return (unsigned(slot) % 9u) % 4u == 0; };  // 3a + a
  // The corner opposite the edge of slot 3a + b (a != b): 3 - a - b.
  static constexpr unsigned kOpposite[9] = {0, 2, 1, 2, 0, 0, 1, 0, 0};
  const auto area_sum = [&](std::span<const int> slots) {
    double area = 0.0;
    for (const int slot : slots) area += face_area_[unsigned(slot) / 9u];
    return area;
  };
  if (update_mass) mass_.resize(std::size_t(pattern_.non_zeros()));
  if (update_stiffness) stiffness_.resize(std::size_t(pattern_.non_zeros()));
  if (update_mass && !update_stiffness) {
    parallel_for_indices<Eigen::Index>(pattern_.non_zeros(), 4096, [&](Eigen::Index nz) {
      const std::span<const int> slots = pattern_.slots(nz);
      mass_[std::size_t(nz)] =
          area_sum(slots) * (is_diagonal_slot(slots.front()) ? diagonal_share : off_share);
    });
    return;
  }
  const std::vector<int>& outer = pattern_.outer();
  parallel_for_indices<Eigen::Index>(Eigen::Index(outer.size()) - 1, 1024, [&](Eigen::Index j) {
    double off_sum = 0.0;
    int diagonal = -1;
    for (int nz = outer[std::size_t(j)]; nz < outer[std::size_t(j) + 1]; ++nz) {
      const std::span<const int> slots = pattern_.slots(nz);
      if (is_diagonal_slot(slots.front())) {
        if (update_mass) mass_[std::size_t(nz)] = area_sum(slots) * diagonal_share;
        diagonal = nz;
        continue;
      }
      double area = 0.0, w = 0.0;
      for (const int slot : slots) {
        const unsigned f = unsigned(slot) / 9u, ab = unsigned(slot) - 9u * f;
        if (update_mass) area += face_area_[f];
        w += corner_weight_[3u * f + kOpposite[ab]];
      }
      if (update_mass) mass_[std::size_t(nz)] = area * off_share;
      stiffness_[std::size_t(nz)] = -w;
      off_sum -= w;
    }
    if (diagonal >= 0) stiffness_[std::size_t(diagonal)] = -off_sum;
  });
}

}  // namespace mcf
