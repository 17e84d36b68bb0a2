#include "bases/clip.h"
#include "bases/cubature.h"
#include "bases/octree.h"
#include "bases/octree_system.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "test_meshes.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <tuple>
#include <utility>
#include <vector>

namespace {

struct Fixture {
  mcf::TriangleMesh mesh;
  mcf::Octree octree;
  std::vector<mcf::ClippedTriangle> pieces;
  std::vector<int> piece_cells;
};

Fixture make_fixture(int depth, mcf::OctreeCube cube_kind = mcf::OctreeCube::tight, int level = 3) {
  Fixture f;
  f.mesh = test_icosphere(level, 1.0);
  f.mesh.vertices = f.mesh.vertices * test_random_rotation(3).transpose();
  const auto cube = mcf::choose_cube(f.mesh, depth, cube_kind);
  f.pieces = mcf::clip_mesh(f.mesh.vertices, f.mesh.faces, cube);
  f.octree = mcf::build_octree(cube, f.pieces, 2);
  f.piece_cells = mcf::locate_pieces(f.octree, f.pieces);
  return f;
}

// The system's mass and stiffness as matrices of their own (assemble() gives values on the
// system's pattern, view() shows them as matrices).
std::pair<mcf::SparseMatrix, mcf::SparseMatrix> assembled(const mcf::OctreeSystem& sys,
                                                          const mcf::CubatureRule& rule) {
  std::vector<double> m, k;
  sys.assemble(rule, m, k);
  return {mcf::SparseMatrix(sys.view(m)), mcf::SparseMatrix(sys.view(k))};
}

TEST(Octree, CubeChoice) {
  auto inside = test_icosphere(2, 0.3, Eigen::Vector3d(0.5, 0.5, 0.5));
  auto g = mcf::choose_cube(inside, 6, mcf::OctreeCube::automatic);
  EXPECT_EQ(g.origin, Eigen::Vector3d::Zero());
  EXPECT_EQ(g.side, 1.0);
  auto sphere = test_icosphere(2, 1.0);
  EXPECT_THROW(mcf::choose_cube(sphere, 6, mcf::OctreeCube::unit), std::invalid_argument);
  for (auto kind : {mcf::OctreeCube::automatic, mcf::OctreeCube::tight}) {
    g = mcf::choose_cube(sphere, 6, kind);
    const double h = g.cell_size();
    EXPECT_NEAR(g.cell_size(), g.side / 64.0, 1e-15);
    for (int a = 0; a < 3; ++a) {  // margin at least half a cell on each side
      EXPECT_GE(sphere.vertices.col(a).minCoeff() - g.origin[a], 0.5 * h);
      EXPECT_GE(g.origin[a] + g.side - sphere.vertices.col(a).maxCoeff(), 0.5 * h);
    }
    EXPECT_LT(g.side, 2.1);
  }
  g = mcf::choose_cube(inside, 6, mcf::OctreeCube::tight);
  EXPECT_LT(g.side, 0.7);
}

// The cube is the surface's: a vertex no face uses, even far outside [0, 1]^3, neither makes
// "auto" leave the unit cube nor "unit" refuse the mesh, nor sizes the tight cube.
TEST(Octree, CubeChoiceIgnoresUnusedVertices) {
  const auto inside = test_icosphere(2, 0.3, Eigen::Vector3d(0.5, 0.5, 0.5));
  auto stray = inside;
  stray.vertices.conservativeResize(inside.vertices.rows() + 1, 3);
  stray.vertices.row(inside.vertices.rows()) = Eigen::RowVector3d(7, -3, 2);
  for (auto kind : {mcf::OctreeCube::automatic, mcf::OctreeCube::unit, mcf::OctreeCube::tight}) {
    const auto a = mcf::choose_cube(inside, 6, kind), b = mcf::choose_cube(stray, 6, kind);
    EXPECT_EQ(a.origin, b.origin);
    EXPECT_EQ(a.side, b.side);
  }
  EXPECT_EQ(mcf::choose_cube(stray, 6, mcf::OctreeCube::automatic).side, 1.0);
}

TEST(Octree, LevelsAreConsistent) {
  const auto f = make_fixture(6);
  ASSERT_EQ(f.octree.num_levels(), 5);  // depths 2..6
  for (int l = 0; l < f.octree.num_levels(); ++l) {
    const auto& L = f.octree.levels[l];
    EXPECT_EQ(L.depth, 2 + l);
    EXPECT_TRUE(std::is_sorted(L.cells.begin(), L.cells.end()));
    EXPECT_TRUE(std::adjacent_find(L.cells.begin(), L.cells.end()) == L.cells.end());
    EXPECT_TRUE(std::is_sorted(L.functions.begin(), L.functions.end()));
    EXPECT_TRUE(std::adjacent_find(L.functions.begin(), L.functions.end()) == L.functions.end());
    std::vector<char> used(L.functions.size(), 0);
    for (std::size_t c = 0; c < L.cells.size(); ++c) {
      const auto ijk = mcf::grid_index(L.cells[c]);
      for (int q = 0; q < 8; ++q) {
        const int fn = L.cell_functions[c][q];
        ASSERT_GE(fn, 0);
        used[fn] = 1;
        const auto o = mcf::corner_offset(q);
        const auto fijk = mcf::grid_index(L.functions[fn]);
        for (int a = 0; a < 3; ++a) EXPECT_EQ(fijk[a], ijk[a] + o[a]);
      }
      if (l > 0) {
        const int p = L.cell_parent[c];
        ASSERT_GE(p, 0);
        const auto pijk = mcf::grid_index(f.octree.levels[l - 1].cells[p]);
        for (int a = 0; a < 3; ++a) EXPECT_EQ(pijk[a], ijk[a] >> 1);
      }
    }
    EXPECT_EQ(std::count(used.begin(), used.end(), 0), 0) << "a function that is no active corner";
    EXPECT_EQ(L.find_function(-1, 0, 0), -1);
  }
  // Finest active cells are exactly the pieces' cells.
  std::vector<mcf::GridKey> keys;
  for (const auto& p : f.pieces) keys.push_back(p.cell);
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  EXPECT_EQ(keys, f.octree.finest().cells);
}

// Σ_fine P_fc B_f(p) == B_c(p) for every coarse function c at random surface points.
TEST(Octree, ProlongationReproducesCoarseFunctions) {
  const auto f = make_fixture(6);
  const auto P = mcf::build_prolongations(f.octree);
  ASSERT_EQ(static_cast<int>(P.size()), f.octree.num_levels() - 1);
  const auto pts = test_surface_points(f.mesh, 200, 5);
  const auto fine_stencils = mcf::point_stencils(f.octree, pts);
  const int finest = f.octree.num_levels() - 1;
  // Finest cell of each point, then its ancestors.
  std::vector<int> cell(pts.rows());
  for (Eigen::Index i = 0; i < pts.rows(); ++i) {
    // The stencil's corner 0 function minus nothing: recover the cell from its function.
    const auto& L = f.octree.finest();
    const auto ijk = mcf::grid_index(L.functions[fine_stencils[i].functions[0]]);
    cell[i] = L.find_cell(ijk[0], ijk[1], ijk[2]);
    ASSERT_GE(cell[i], 0);
  }
  for (int l = finest - 1; l >= 0; --l) {
    const auto& Pl = P[l];
    EXPECT_EQ(Pl.rows(), f.octree.levels[l + 1].num_functions());
    EXPECT_EQ(Pl.cols(), f.octree.levels[l].num_functions());
    for (Eigen::Index i = 0; i < pts.rows(); ++i) {
      const int fine_cell = cell[i];
      const int coarse_cell = f.octree.levels[l + 1].cell_parent[fine_cell];
      const auto bf = mcf::cell_stencil(f.octree, l + 1, fine_cell, pts.row(i).transpose());
      const auto bc = mcf::cell_stencil(f.octree, l, coarse_cell, pts.row(i).transpose());
      Eigen::VectorXd fine = Eigen::VectorXd::Zero(Pl.rows());
      for (int q = 0; q < 8; ++q) fine[bf.functions[q]] += bf.weights[q];
      Eigen::VectorXd coarse_from_fine = Pl.transpose() * fine;  // Σ_f P_fc B_f(p)
      Eigen::VectorXd coarse = Eigen::VectorXd::Zero(Pl.cols());
      for (int q = 0; q < 8; ++q) coarse[bc.functions[q]] += bc.weights[q];
      EXPECT_LT((coarse_from_fine - coarse).cwiseAbs().maxCoeff(), 1e-14)
          << "level " << l << " point " << i;
      cell[i] = coarse_cell;
    }
  }
}

TEST(Octree, GalerkinEqualsDirectCoarseAssembly) {
  const auto f = make_fixture(6);
  const auto P = mcf::build_prolongations(f.octree);
  const int finest = f.octree.num_levels() - 1;
  for (int order : {1, 3}) {
    const auto& rule = mcf::cubature_rule(order);
    mcf::OctreeSystem fine_sys(f.octree, finest, f.pieces, f.piece_cells);
    auto [M, K] = assembled(fine_sys, rule);
    for (int l = finest - 1; l >= finest - 3; --l) {
      M = mcf::SparseMatrix(P[l].transpose() * M * P[l]);
      K = mcf::SparseMatrix(P[l].transpose() * K * P[l]);
      mcf::OctreeSystem coarse_sys(f.octree, l, f.pieces, f.piece_cells);
      const auto [Mc, Kc] = assembled(coarse_sys, rule);
      ASSERT_EQ(Mc.rows(), M.rows());
      const mcf::SparseMatrix dM = M - Mc, dK = K - Kc;
      const double em = dM.coeffs().cwiseAbs().maxCoeff(), ek = dK.coeffs().cwiseAbs().maxCoeff();
      EXPECT_LT(em, 1e-12 * Mc.coeffs().cwiseAbs().maxCoeff()) << "level " << l;
      EXPECT_LT(ek, 1e-11 * Kc.coeffs().cwiseAbs().maxCoeff()) << "level " << l;
      // And it is not trivially zero.
      EXPECT_GT(Mc.sum(), 1.0);
    }
  }
}

TEST(Octree, PatternIsSymmetricAndColoursSeparateNeighbours) {
  const auto f = make_fixture(5);
  const auto colours = mcf::build_colours(f.octree);
  ASSERT_EQ(static_cast<int>(colours.size()), f.octree.num_levels());
  mcf::OctreeSystem sys(f.octree, f.octree.num_levels() - 1, f.pieces, f.piece_cells);
  const auto& A = sys.pattern();
  EXPECT_TRUE(A.isCompressed());
  const auto& col = colours.back();
  for (int J = 0; J < A.outerSize(); ++J) {
    EXPECT_TRUE(std::is_sorted(A.innerIndexPtr() + A.outerIndexPtr()[J],
                               A.innerIndexPtr() + A.outerIndexPtr()[J + 1]));
    for (mcf::SparseMatrix::InnerIterator it(A, J); it; ++it) {
      if (it.row() != J) {
        EXPECT_NE(col[it.row()], col[J]);
      }
    }
  }
  const mcf::SparseMatrix At = A.transpose();
  EXPECT_EQ(At.nonZeros(), A.nonZeros());
  for (int J = 0; J < A.outerSize(); ++J)
    for (int s = A.outerIndexPtr()[J]; s < A.outerIndexPtr()[J + 1]; ++s)
      EXPECT_EQ(A.innerIndexPtr()[s], At.innerIndexPtr()[s]);
}

}  // namespace

#include <tbb/global_control.h>

namespace {

TEST(Octree, AssemblyIsDeterministicAcrossThreadCounts) {
  const auto f = make_fixture(6);
  const int finest = f.octree.num_levels() - 1;
  mcf::SparseMatrix M1, K1, M2, K2;
  {
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    mcf::OctreeSystem sys(f.octree, finest, f.pieces, f.piece_cells);
    std::tie(M1, K1) = assembled(sys, mcf::cubature_rule(3));
  }
  {
    tbb::global_control many(tbb::global_control::max_allowed_parallelism, 4);
    const auto pieces = mcf::clip_mesh(f.mesh.vertices, f.mesh.faces, f.octree.cube);
    ASSERT_EQ(pieces.size(), f.pieces.size());
    mcf::OctreeSystem sys(f.octree, finest, pieces, f.piece_cells);
    std::tie(M2, K2) = assembled(sys, mcf::cubature_rule(3));
  }
  ASSERT_EQ(M1.nonZeros(), M2.nonZeros());
  for (Eigen::Index s = 0; s < M1.nonZeros(); ++s) {
    ASSERT_EQ(M1.valuePtr()[s], M2.valuePtr()[s]);
    ASSERT_EQ(K1.valuePtr()[s], K2.valuePtr()[s]);
  }
}

}  // namespace
