// The octree mass and stiffness against a brute-force assembly written straight from the
// definitions (docs/design.md "The octree basis"), sharing no code with the bases' per-cell kernel
// (bases/cell_blocks.h), its tiles or its slot table: every function is evaluated from B_ijk(p) =
// Π_a max(0, 1 - |p_a/h - idx_a|), gradients are projected onto the piece's plane
// in 3-D (no tangent frame), and entries are summed into a dense map keyed by (I, J).
//   rebuilt:  M_IJ = Σ w B_I B_J,            K_IJ = Σ w ∇_T B_I · ∇_T B_J
//   tracked:  dX = Σ_I x_I ⊗ ∇_T B_I (3x3, rank 2 on the tangent plane), g = dXᵀdX on the plane,
//             M_IJ = Σ w √|g| B_I B_J,       K_IJ = Σ w √|g| ∇_T B_Iᵀ g⁺ ∇_T B_J
// with g⁺ the pseudo-inverse of the 3x3 metric restricted to the plane (frame-free form of g⁻¹).

#include "bases/cubature.h"
#include "bases/tracked_octree_basis.h"
#include "test_meshes.h"

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>

#include <cmath>
#include <map>
#include <random>
#include <utility>

namespace mcf {
namespace {

using Entries = std::map<std::pair<int, int>, double>;

struct Reference {
  Entries mass, stiffness;
};

/// Brute force over every piece and cubature point; x = nullptr: identity metric (rebuilt).
Reference brute_force(const RebuiltOctreeBasis& basis, int cubature, const Coefficients* x) {
  const Octree& octree = basis.octree();
  const OctreeLevel& L = octree.finest();
  const double h = octree.cube.cell_size(L.depth);
  const CubatureRule& rule = cubature_rule(cubature);
  Reference ref;
  for (const ClippedTriangle& t : basis.pieces()) {
    const Eigen::Vector3d p0 = t.corner(0), p1 = t.corner(1), p2 = t.corner(2);
    const Eigen::Vector3d cr = (p1 - p0).cross(p2 - p0);
    const double area = 0.5 * cr.norm();
    if (!(area > 0)) continue;
    const Eigen::Vector3d n = cr.normalized();
    const Eigen::Matrix3d tangent = Eigen::Matrix3d::Identity() - n * n.transpose();
    for (int q = 0; q < rule.size(); ++q) {
      const auto& b = rule.points[std::size_t(q)];
      const Eigen::Vector3d p = b[0] * p0 + b[1] * p1 + b[2] * p2;
      const Eigen::Vector3d u = (p - octree.cube.origin) / h;
      // Every function whose support contains p: the corners of the grid cells around it.
      std::vector<int> ids;
      std::vector<double> values;
      std::vector<Eigen::Vector3d> grads;
      const int i0 = int(std::floor(u[0])) - 1, j0 = int(std::floor(u[1])) - 1,
                k0 = int(std::floor(u[2])) - 1;
      for (int k = k0; k <= k0 + 3; ++k)
        for (int j = j0; j <= j0 + 3; ++j)
          for (int i = i0; i <= i0 + 3; ++i) {
            const double d[3] = {u[0] - i, u[1] - j, u[2] - k};
            double f[3], df[3];
            bool inside = true;
            for (int a = 0; a < 3; ++a) {
              f[a] = std::max(0.0, 1.0 - std::abs(d[a]));
              df[a] = std::abs(d[a]) < 1.0 ? (d[a] > 0 ? -1.0 : 1.0) / h : 0.0;
              inside = inside && std::abs(d[a]) < 1.0;
            }
            if (!inside) continue;
            const int I = L.find_function(i, j, k);
            if (I < 0) {
              ADD_FAILURE() << "function (" << i << "," << j << "," << k
                            << ") has support at a surface point but is inactive";
              continue;
            }
            ids.push_back(I);
            values.push_back(f[0] * f[1] * f[2]);
            grads.push_back(tangent * Eigen::Vector3d(df[0] * f[1] * f[2], f[0] * df[1] * f[2],
                                                      f[0] * f[1] * df[2]));
          }
      double wm = area * rule.weights[std::size_t(q)];
      Eigen::Matrix3d S = wm * Eigen::Matrix3d::Identity();
      if (x != nullptr) {
        Eigen::Matrix3d dX = Eigen::Matrix3d::Zero();  // dX v = Σ x_I (∇_T B_I · v)
        for (std::size_t a = 0; a < ids.size(); ++a)
          dX += x->row(ids[a]).transpose() * grads[a].transpose();
        const Eigen::Matrix3d g = tangent * dX.transpose() * dX * tangent;
        // Restricted to the plane: eigenvalues of g on the plane give det and the pseudo-inverse.
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(
            g + n * n.transpose());  // n ↦ 1 off the plane
        const double det = es.eigenvalues().prod();
        wm *= std::sqrt(det);
        const Eigen::Matrix3d inv = es.eigenvectors() *
                                    es.eigenvalues().cwiseInverse().asDiagonal() *
                                    es.eigenvectors().transpose();
        S = wm * tangent * inv * tangent;
      }
      for (std::size_t a = 0; a < ids.size(); ++a)
        for (std::size_t c = 0; c < ids.size(); ++c) {
          ref.mass[{ids[a], ids[c]}] += wm * values[a] * values[c];
          ref.stiffness[{ids[a], ids[c]}] += grads[a].dot(S * grads[c]);
        }
    }
  }
  return ref;
}

/// max |A_IJ - ref_IJ| / max |ref|, over the union of both patterns.
double max_relative_error(const SparseMatrix& A, const Entries& ref) {
  double scale = 0, err = 0;
  for (const auto& [ij, v] : ref) scale = std::max(scale, std::abs(v));
  Entries seen;
  for (int J = 0; J < A.outerSize(); ++J)
    for (SparseMatrix::InnerIterator it(A, J); it; ++it) {
      const auto key = std::make_pair(int(it.row()), J);
      const auto f = ref.find(key);
      err = std::max(err, std::abs(it.value() - (f == ref.end() ? 0.0 : f->second)));
      seen[key] = 1;
    }
  for (const auto& [ij, v] : ref)
    if (!seen.count(ij)) err = std::max(err, std::abs(v));
  return err / scale;
}

TEST(OctreeBruteForce, RebuiltMassAndStiffness) {
  const TriangleMesh mesh = test_icosphere(2, 0.9);
  for (int cubature : {1, 3, 6}) {
    RebuiltOctreeBasis basis(mesh, OctreeOptions{.depth = 4, .cubature = cubature});
    const Reference ref = brute_force(basis, cubature, nullptr);
    EXPECT_LT(max_relative_error(basis.mass(), ref.mass), 1e-12) << cubature;
    EXPECT_LT(max_relative_error(basis.stiffness(), ref.stiffness), 1e-12) << cubature;
  }
}

TEST(OctreeBruteForce, TrackedAtADeformedEmbedding) {
  const TriangleMesh mesh = test_icosphere(2, 0.9);
  for (int cubature : {1, 3}) {
    TrackedOctreeBasis tracked(mesh, OctreeOptions{.depth = 4, .cubature = cubature});
    // A smooth anisotropic deformation plus noise: a metric far from the identity everywhere.
    Coefficients x = tracked.initial_coefficients();
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> noise(-0.01, 0.01);
    for (Eigen::Index i = 0; i < x.rows(); ++i) {
      const Eigen::Vector3d c = x.row(i);
      x.row(i) = Eigen::Vector3d(1.3 * c[0] + 0.2 * c[1] * c[1], 0.7 * c[1] + 0.1 * c[2],
                                 c[2] + 0.3 * c[0] * c[1]) +
                 Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    }
    tracked.update(x, true, true);
    ASSERT_EQ(tracked.degenerate_points(), 0);
    // The tracked basis freed its pieces; a rebuilt basis with the same options has the same
    // pieces and function numbering.
    const Reference ref = brute_force(
        RebuiltOctreeBasis(mesh, OctreeOptions{.depth = 4, .cubature = cubature}), cubature, &x);
    EXPECT_LT(max_relative_error(tracked.mass(), ref.mass), 1e-11) << cubature;
    EXPECT_LT(max_relative_error(tracked.stiffness(), ref.stiffness), 1e-11) << cubature;
    // Mass only and stiffness only give the same values (the cMCF and heat paths).
    const SparseMatrix M = tracked.mass(), K = tracked.stiffness();
    tracked.update(tracked.initial_coefficients(), true, true);
    tracked.update(x, true, false);
    EXPECT_LT((tracked.mass() - M).norm(), 1e-14 * M.norm());
    tracked.update(x, false, true);
    EXPECT_LT((tracked.stiffness() - K).norm(), 1e-14 * K.norm());
  }
}

}  // namespace
}  // namespace mcf
