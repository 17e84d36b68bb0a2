#pragma once
// The normal-gradient matrix of the octree's band (docs/octree-multigrid.md, "Stabilization"):
//   S_IJ = ∫_band (n·∇B_I)(n·∇B_J) dV,
// the band being the finest level's active cells and n, in each cell, the unit area-weighted
// normal of the surface pieces clipped to it (Σ_p (p1 - p0) × (p2 - p0), normalised). A function
// constant along n has zero S-energy, so adding ρ S to a system whose unknown is an increment
// of the surface (a velocity extended constantly along normals) is consistent, while the
// restricted B-splines' near-null combinations (smooth functions that nearly vanish on the
// surface, whose gradient points along n) get an energy of order ρ. Burman, Hansbo, Larson,
// Massing 2018; Grande, Lehrenfeld, Reusken 2018 ("volume normal derivative" stabilization).
//
// n is constant per cell, so (n·∇B_a)(n·∇B_b) is a polynomial of degree at most 2 in each
// coordinate and a 2-point Gauss rule per axis integrates it exactly: each cell's 8x8 block is
// h Σ_ij n_i n_j T_ij(a, b) with T the unit cell's integrals of ∂_i B_a ∂_j B_b.

#include "bases/clip.h"
#include "bases/octree.h"
#include "bases/octree_system.h"

#include <vector>

namespace mcf {

/// The unit cell's tables: T[3 i + j][8 a + b] = ∫_[0,1]^3 ∂_i B_a ∂_j B_b dt (corner order of
/// corner_offset). Symmetric in (i, j) with (a, b) swapped.
const std::array<std::array<double, 64>, 9>& unit_gradient_tables();

/// The band's unit normals per finest cell (octree.finest() order) from the pieces and their
/// finest cells (locate_pieces). A cell whose pieces' normals cancel exactly (zero sum) gets the
/// zero vector, and its block of S is zero.
std::vector<Eigen::Vector3d> cell_normals(const Octree& octree,
                                          const std::vector<ClippedTriangle>& pieces,
                                          const std::vector<int>& piece_cells);

/// S on the finest system's pattern (values in its CSC order, full symmetric storage): the
/// blocks of all finest cells accumulated lock-free in the system's tile order (parallel,
/// independent of the thread count). `system` must be the finest level's.
std::vector<double> assemble_normal_gradient(const OctreeSystem& system, const Octree& octree,
                                             const std::vector<Eigen::Vector3d>& normals);

}  // namespace mcf
