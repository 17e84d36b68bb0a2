#pragma once
// The octree that indexes trilinear B-splines (docs/design.md "The octree basis").
// A grid of depth d over a cube (origin, side); cell (i,j,k) at depth l is the box
// origin + h_l [i,i+1]x[j,j+1]x[k,k+1], h_l = side / 2^l; function (i,j,k) at depth l is centred
// at the grid vertex origin + h_l (i,j,k). Cells and functions of a level are stored sorted by
// their GridKey (k major, then j, then i), so a neighbour offset order (dz,dy,dx) maps
// monotonically to index order; lookups are binary searches.

#include "datasets/mesh.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <vector>

namespace mcf {

enum class OctreeCube {
  unit,       ///< [0,1]^3 (the mesh must lie inside it)
  tight,      ///< bounding cube of the mesh, enlarged by 1% plus half a finest cell
  automatic,  ///< unit if the mesh lies inside [0,1]^3, tight otherwise
};

struct GridCube {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  double side = 1.0;
  int depth = 8;  ///< finest depth
  int resolution(int level_depth) const { return 1 << level_depth; }
  double cell_size(int level_depth) const { return side / static_cast<double>(1 << level_depth); }
  int resolution() const { return resolution(depth); }
  double cell_size() const { return cell_size(depth); }
};

/// Chooses the cube for a depth in [1, 20] (the basis accepts 4..10) from the surface's bounds
/// (the vertices its faces use: datasets/referenced_vertices.h). Throws std::invalid_argument for
/// `unit` when such a vertex lies outside [0,1]^3, and for an empty or single-point mesh.
GridCube choose_cube(const TriangleMesh& mesh, int depth, OctreeCube cube);

using GridKey = std::uint64_t;
inline constexpr int kGridKeyBits = 21;
inline GridKey grid_key(int i, int j, int k) {
  return (static_cast<GridKey>(k) << (2 * kGridKeyBits)) |
         (static_cast<GridKey>(j) << kGridKeyBits) | static_cast<GridKey>(i);
}
inline std::array<int, 3> grid_index(GridKey key) {
  constexpr GridKey mask = (GridKey(1) << kGridKeyBits) - 1;
  return {static_cast<int>(key & mask), static_cast<int>((key >> kGridKeyBits) & mask),
          static_cast<int>(key >> (2 * kGridKeyBits))};
}
/// Corner c of a cell is offset ((c&1), (c>>1)&1, (c>>2)&1) from the cell's index.
inline std::array<int, 3> corner_offset(int c) {
  return {c & 1, (c >> 1) & 1, (c >> 2) & 1};
}

struct OctreeLevel {
  int depth = 0;
  std::vector<GridKey> cells;                      ///< active cells, sorted
  std::vector<GridKey> functions;                  ///< corners of active cells, sorted
  std::vector<std::array<int, 8>> cell_functions;  ///< per cell: function index of corner c
  std::vector<int> cell_parent;  ///< per cell: index in the next coarser level (-1 on the coarsest)
  /// Row directories: entries of row (k,j) are [row_start[k*n+j], row_start[k*n+j+1]) with
  /// n = 2^depth (cells) or 2^depth+1 (functions); lookups search only inside one row.
  std::vector<int> cell_row_start, function_row_start;

  /// Index of a cell / function, or -1 when it is not active. Negative indices are never active.
  int find_cell(int i, int j, int k) const;
  int find_function(int i, int j, int k) const;
  Eigen::Index num_functions() const { return static_cast<Eigen::Index>(functions.size()); }
  Eigen::Index num_cells() const { return static_cast<Eigen::Index>(cells.size()); }
};

struct Octree {
  GridCube cube;
  std::vector<OctreeLevel> levels;  ///< coarsest first; levels.back().depth == cube.depth

  const OctreeLevel& finest() const { return levels.back(); }
  int num_levels() const { return static_cast<int>(levels.size()); }
  /// Grid-vertex positions c_I of a level's functions (the identity coefficients).
  Eigen::Matrix<double, Eigen::Dynamic, 3> function_positions(int level) const;
};

/// Builds all levels from the active finest cells (any order, duplicates allowed). Levels run from
/// depth min(coarsest_depth, cube.depth) up to cube.depth. Parallel (TBB sorts and loops).
Octree build_octree(const GridCube& cube, std::vector<GridKey> finest_cells,
                    int coarsest_depth = 2);

}  // namespace mcf
