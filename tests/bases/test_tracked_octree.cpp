// The tracked basis against the rebuilt one (same octree, pieces and cubature: at X_0 the two
// integrate the same functions, so the matrices must agree to rounding) and against the
// invariances of the metric: scaling the coefficients by s scales M by s² and leaves K; a
// rotation leaves both.

#include "bases/tracked_octree_basis.h"
#include "datasets/generators.h"
#include "test_meshes.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <algorithm>
#include <vector>

namespace mcf {
namespace {

// Any two sparse matrices: the bases hand out views (SparseView), released values are copied.
template <class A, class B>
double relative_difference(const Eigen::SparseMatrixBase<A>& a,
                           const Eigen::SparseMatrixBase<B>& b) {
  return SparseMatrix(a.derived() - b.derived()).norm() / b.derived().norm();
}

TEST(TrackedOctree, StepZeroEqualsRebuilt) {
  const TriangleMesh mesh = test_icosphere(3, 1.0);
  for (int cubature : {1, 3, 6}) {
    OctreeOptions o;
    o.depth = 6;
    o.cubature = cubature;
    TrackedOctreeBasis tracked(mesh, o);
    // An independently constructed rebuilt basis (same octree, pieces and function numbering).
    RebuiltOctreeBasis fresh(mesh, o);
    EXPECT_LT(relative_difference(tracked.mass(), fresh.mass()), 1e-12) << cubature;
    EXPECT_LT(relative_difference(tracked.stiffness(), fresh.stiffness()), 1e-12) << cubature;
    // The tracked basis took over the initial assembly's matrices and freed its pieces.
    EXPECT_EQ(tracked.initial().mass().nonZeros(), 0) << cubature;
    EXPECT_EQ(tracked.initial().stiffness().nonZeros(), 0) << cubature;
    EXPECT_TRUE(tracked.initial().pieces().empty()) << cubature;
    EXPECT_EQ(tracked.mass().nonZeros(), fresh.mass().nonZeros()) << cubature;
    std::vector<double> M, K;
    EXPECT_THROW(tracked.initial().system().assemble(cubature_rule(cubature), M, K),
                 std::logic_error)
        << cubature;
    EXPECT_TRUE(M.empty() && K.empty()) << cubature;  // outputs untouched by the refusal
    // What only the assembly read is freed too (OctreeSystem::release_pieces): the piece order and
    // cells and the initial basis's stencils. The pattern stays: mass and stiffness are values on
    // it, both shown through its one copy of the index arrays.
    const OctreeSystem& system = tracked.initial().system();
    EXPECT_TRUE(system.pieces_released()) << cubature;
    EXPECT_TRUE(system.piece_order().empty() && system.piece_cell().empty()) << cubature;
    EXPECT_EQ(system.non_zeros(), fresh.mass().nonZeros()) << cubature;
    EXPECT_EQ(tracked.mass().outerIndexPtr(), system.outer().data()) << cubature;
    EXPECT_EQ(tracked.stiffness().outerIndexPtr(), system.outer().data()) << cubature;
    EXPECT_EQ(tracked.mass().innerIndexPtr(), tracked.stiffness().innerIndexPtr()) << cubature;
    const SparseMatrix pattern = system.pattern();
    EXPECT_TRUE(std::equal(pattern.innerIndexPtr(), pattern.innerIndexPtr() + pattern.nonZeros(),
                           fresh.mass().innerIndexPtr()) &&
                std::equal(pattern.outerIndexPtr(), pattern.outerIndexPtr() + pattern.cols() + 1,
                           fresh.mass().outerIndexPtr()))
        << cubature;
    EXPECT_THROW((void)tracked.initial().evaluate_vertices(tracked.initial_coefficients()),
                 std::logic_error)
        << cubature;
    EXPECT_EQ(tracked.evaluate_vertices(tracked.initial_coefficients()).rows(),
              mesh.num_vertices());
    EXPECT_LT((tracked.evaluate_vertices(tracked.initial_coefficients()) - mesh.vertices)
                  .cwiseAbs()
                  .maxCoeff(),
              1e-12);
  }
}

// A released rebuilt basis is whole again after rebuild(): same matrices, stencils back.
TEST(TrackedOctree, RebuildAfterReleaseStartsOver) {
  const TriangleMesh mesh = test_icosphere(2, 1.0);
  OctreeOptions o;
  o.depth = 5;
  RebuiltOctreeBasis fresh(mesh, o), released(mesh, o);
  std::vector<double> M, K, S;
  released.release_assembly(M, K, S);
  EXPECT_TRUE(S.empty());  // not asked for
  EXPECT_EQ(relative_difference(released.system().view(M), fresh.mass()), 0.0);
  EXPECT_EQ(relative_difference(released.system().view(K), fresh.stiffness()), 0.0);
  EXPECT_EQ(released.mass().nonZeros() + released.stiffness().nonZeros(), 0);
  released.rebuild(mesh.vertices);
  EXPECT_FALSE(released.system().pieces_released());
  EXPECT_EQ(relative_difference(released.mass(), fresh.mass()), 0.0);
  EXPECT_EQ(relative_difference(released.stiffness(), fresh.stiffness()), 0.0);
  EXPECT_EQ(released.evaluate_vertices(released.initial_coefficients()),
            fresh.evaluate_vertices(fresh.initial_coefficients()));
}

TEST(TrackedOctree, InitialMetricIsIdentity) {
  const TriangleMesh mesh = test_icosphere(2, 0.8);
  OctreeOptions o;
  o.depth = 5;
  TrackedOctreeBasis tracked(mesh, o);
  EXPECT_LT(tracked.max_metric_deviation(tracked.initial_coefficients()), 1e-12);
  EXPECT_NEAR(tracked.max_metric_deviation(2.0 * tracked.initial_coefficients()), 3.0,
              1e-12);  // g = 4 I
  EXPECT_EQ(tracked.degenerate_points(), 0);
}

TEST(TrackedOctree, MetricInvariances) {
  const TriangleMesh mesh = test_icosphere(3, 1.0);
  OctreeOptions o;
  o.depth = 5;
  TrackedOctreeBasis tracked(mesh, o);
  const SparseMatrix M0 = tracked.mass(), K0 = tracked.stiffness();
  const Coefficients x0 = tracked.initial_coefficients();
  tracked.update(2.5 * x0, true, true);
  EXPECT_LT(relative_difference(tracked.mass(), 6.25 * M0), 1e-12);
  EXPECT_LT(relative_difference(tracked.stiffness(), K0), 1e-12);
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  tracked.update((x0 * R.transpose()).rowwise() + Eigen::RowVector3d(1, -2, 3), true, true);
  EXPECT_LT(relative_difference(tracked.mass(), M0), 1e-12);
  EXPECT_LT(relative_difference(tracked.stiffness(), K0), 1e-12);
  // A non-conformal stretch changes K (g⁻¹ is no longer a multiple of I).
  Coefficients stretched = x0;
  stretched.col(0) *= 2.0;
  tracked.update(stretched, true, true);
  EXPECT_GT(relative_difference(tracked.stiffness(), K0), 1e-3);
}

TEST(TrackedOctree, DegenerateMetricContributesNothing) {
  const TriangleMesh mesh = test_icosphere(2, 1.0);
  OctreeOptions o;
  o.depth = 4;
  TrackedOctreeBasis tracked(mesh, o);
  // Collapse everything onto a line: every metric has rank <= 1.
  Coefficients line = tracked.initial_coefficients();
  line.col(1).setZero();
  line.col(2).setZero();
  tracked.update(line, true, true);
  EXPECT_EQ(tracked.degenerate_points(), tracked.stats().cubature_points);
  EXPECT_EQ(tracked.mass().norm(), 0.0);
  EXPECT_EQ(tracked.stiffness().norm(), 0.0);
}

TEST(TrackedOctree, ThreadCountDoesNotChangeTheResult) {
  const TriangleMesh mesh = test_icosphere(3, 1.0);
  OctreeOptions o;
  o.depth = 6;
  TrackedOctreeBasis tracked(mesh, o);
  Coefficients x = tracked.initial_coefficients();
  x.col(2) *= 0.7;
  SparseMatrix M1, K1;
  {
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    tracked.update(x, true, true);
    M1 = tracked.mass();
    K1 = tracked.stiffness();
  }
  tracked.update(x, true, true);
  ASSERT_EQ(M1.nonZeros(), tracked.mass().nonZeros());
  for (Eigen::Index i = 0; i < M1.nonZeros(); ++i) {
    ASSERT_EQ(M1.valuePtr()[i], tracked.mass().valuePtr()[i]);
    ASSERT_EQ(K1.valuePtr()[i], tracked.stiffness().valuePtr()[i]);
  }
}

TEST(TrackedOctree, LeanStorage) {
  const TriangleMesh mesh = test_icosphere(3, 1.0);
  OctreeOptions o;
  o.depth = 6;
  o.cubature = 3;
  TrackedOctreeBasis tracked(mesh, o);
  // The paper stores 25 floats = 100 bytes per point; 9 doubles per split triangle would be 24
  // bytes per point of the 3-point rule, and the fans store less (3 doubles per continuation).
  const double pieces = double(tracked.stats().split_triangles);
  const double continuations = double(tracked.fan_continuations());
  EXPECT_GT(continuations, 0.2 * pieces);
  const double fan_bytes = 8.0 * (9.0 * pieces - 6.0 * continuations + 1.0) + pieces;
  EXPECT_NEAR(double(tracked.preprocessed_bytes()) - fan_bytes,
              8.0 * double(tracked.initial().octree().finest().cells.size() + 1), 0.5);
  EXPECT_LT(tracked.stats().bytes_per_cubature_point, 24.0);
  EXPECT_LT(tracked.stats().bytes_per_cubature_point, 100.0 / 3.0);
}

// The fans hold every piece's corners: decoded, they are the pieces' own cell-local corners, in the
// system's piece order (an independently built rebuilt basis). The fans store the library's
// numbers bitwise, but the reference here is computed by this file, whose compiler flags may fuse
// (x - o) * inv_h - i otherwise; a corner lost or misplaced is off by far more than 1e-14 of a
// cell.
TEST(TrackedOctree, FansHoldEveryPiecesCorners) {
  const TriangleMesh mesh = make_torus(1.0, 0.35, 48, 24);
  OctreeOptions o;
  o.depth = 6;
  TrackedOctreeBasis tracked(mesh, o);
  RebuiltOctreeBasis fresh(mesh, o);
  const OctreeLevel& L = fresh.octree().finest();
  const GridCube& cube = fresh.octree().cube;
  const double inv_h = 1.0 / cube.cell_size(L.depth);
  const auto& start = fresh.system().cell_start();
  const auto& order = fresh.system().piece_order();
  long long pieces = 0;
  for (std::size_t c = 0; c < L.cells.size(); ++c) {
    std::vector<double> expected;
    const auto ijk = grid_index(L.cells[c]);
    for (int s = start[c]; s < start[c + 1]; ++s, ++pieces) {
      const ClippedTriangle& t = fresh.pieces()[std::size_t(order[std::size_t(s)])];
      for (int v = 0; v < 3; ++v)
        for (int a = 0; a < 3; ++a)
          expected.push_back((t.corners[v][a] - cube.origin[a]) * inv_h - ijk[a]);
    }
    const std::vector<double> decoded = tracked.cell_local_corners(int(c));
    ASSERT_EQ(decoded.size(), expected.size()) << "cell " << c;
    for (std::size_t k = 0; k < expected.size(); ++k)
      ASSERT_NEAR(decoded[k], expected[k], 1e-14) << "cell " << c << ", value " << k;
  }
  EXPECT_EQ(pieces, tracked.stats().split_triangles);
  EXPECT_GT(tracked.fan_continuations(), 0);
}

}  // namespace
}  // namespace mcf
