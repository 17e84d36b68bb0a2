#pragma once
// Integration of trilinear B-splines over clipped pieces (docs/design.md "The octree basis"): per
// piece and cubature point the weight w = area·ω, the 8 values of the cell's corner functions and
// their gradients in an orthonormal frame of the piece's plane (cell_blocks.h); mass and stiffness
// are accumulated into a sparsity pattern built once per octree level. Also the multigrid hierarchy
// (prolongations, parity colours) and vertex evaluation. The pieces are exposed so the tracked
// basis can reuse them.

#include "bases/basis.h"
#include "bases/clip.h"
#include "bases/cubature.h"
#include "bases/octree.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <array>
#include <bit>
#include <cstdint>
#include <vector>

namespace mcf {

/// Values and gradients of the 8 corner functions of a cell at local coordinates t ∈ [0,1]^3
/// (t = (p - cell origin)/h). Corner c as in corner_offset(c). gradient[c] is in world units.
inline void trilinear_values(const double t[3], double inv_h, double value[8],
                             double gradient[8][3]) {
  const double w0[3] = {1.0 - t[0], 1.0 - t[1], 1.0 - t[2]};
  for (int c = 0; c < 8; ++c) {
    const int ox = c & 1, oy = (c >> 1) & 1, oz = (c >> 2) & 1;
    const double bx = ox ? t[0] : w0[0], by = oy ? t[1] : w0[1], bz = oz ? t[2] : w0[2];
    const double sx = ox ? inv_h : -inv_h, sy = oy ? inv_h : -inv_h, sz = oz ? inv_h : -inv_h;
    value[c] = bx * by * bz;
    gradient[c][0] = sx * by * bz;
    gradient[c][1] = bx * sy * bz;
    gradient[c][2] = bx * by * sz;
  }
}

/// Offset bit (0..26) of row function I relative to column function J, both corners of one cell:
/// o = (dz+1)*9 + (dy+1)*3 + (dx+1) with d = corner(a) - corner(b).
constexpr int neighbour_bit(int corner_row, int corner_col) {
  const int dx = (corner_row & 1) - (corner_col & 1),
            dy = ((corner_row >> 1) & 1) - ((corner_col >> 1) & 1),
            dz = ((corner_row >> 2) & 1) - ((corner_col >> 2) & 1);
  return (dz + 1) * 9 + (dy + 1) * 3 + (dx + 1);
}

/// Per (a, b) of a cell's 8x8 block, entry 8a+b: the mask of the neighbour bits below
/// neighbour_bit(a, b) (its rank in column b's neighbour mask). A constant table, so that the
/// unrolled scatter of a cell's blocks is a popcount and an add per entry (computed per entry, the
/// bit arithmetic was a third of the scatter's instructions).
struct CellBlockTables {
  std::uint32_t below[64];
};
constexpr CellBlockTables make_cell_block_tables() {
  CellBlockTables t{};
  for (int a = 0; a < 8; ++a)
    for (int b = 0; b < 8; ++b) t.below[8 * a + b] = (1u << neighbour_bit(a, b)) - 1u;
  return t;
}
inline constexpr CellBlockTables kCellBlockTables = make_cell_block_tables();

/// Integration data of one octree level over fixed pieces: pieces grouped by cell, cells grouped
/// by parity colour, and the CSC pattern of the level's matrices (full symmetric storage).
/// Slot of (I = cell_functions[a], J = cell_functions[b]) is
///   outer[J] + popcount(neighbour_mask[J] & ((1 << neighbour_bit(a,b)) - 1)).
class OctreeSystem {
 public:
  /// `level` indexes octree.levels. piece_finest_cell[p] = index of piece p's cell in the finest
  /// level. Keeps pointers to `octree` and `pieces`: both must outlive the system and stay
  /// unchanged.
  OctreeSystem(const Octree& octree, int level, const std::vector<ClippedTriangle>& pieces,
               const std::vector<int>& piece_finest_cell);

  int level() const { return level_; }
  Eigen::Index dimension() const { return static_cast<Eigen::Index>(outer_.size()) - 1; }
  /// From the column starts, so it stays after release_pieces().
  Eigen::Index non_zeros() const { return outer_.empty() ? 0 : outer_.back(); }
  /// A matrix with this pattern and zero values (compressed, full symmetric storage).
  SparseMatrix pattern() const;
  /// Values on this pattern (non_zeros() of them, in CSC order) seen as a matrix: mass and
  /// stiffness share the system's index arrays instead of each carrying a copy. The view is valid
  /// while the system and `values` are alive and unresized.
  SparseView view(const std::vector<double>& values) const {
    return view_of(outer_, inner_, values);
  }
  /// Column starts (dimension+1) and row indices of the pattern.
  const std::vector<int>& outer() const { return outer_; }
  const std::vector<int>& inner() const { return inner_; }
  int slot(int cell, int corner_row, int corner_col) const {
    const auto& f = octree_->levels[static_cast<std::size_t>(level_)]
                        .cell_functions[static_cast<std::size_t>(cell)];
    const int J = f[static_cast<std::size_t>(corner_col)];
    const std::uint32_t below = (1u << neighbour_bit(corner_row, corner_col)) - 1u;
    return outer_[static_cast<std::size_t>(J)] +
           std::popcount(mask_[static_cast<std::size_t>(J)] & below);
  }
  /// Adds a cell's summed blocks (blocks.mass(a,b), blocks.stiffness(a,b), read for a ≤ b) into
  /// the value arrays of this pattern, the upper triangle mirrored so both halves are equal
  /// (SetSystemMatrices). A null array is skipped.
  template <class Blocks>
  void add_cell_blocks(int cell, const Blocks& blocks, double* mass, double* stiffness) const {
    const auto& f = octree_->levels[static_cast<std::size_t>(level_)]
                        .cell_functions[static_cast<std::size_t>(cell)];
#pragma GCC unroll 8
    for (int b = 0; b < 8; ++b) {
      const auto J = static_cast<std::size_t>(f[static_cast<std::size_t>(b)]);
      const int base = outer_[J];
      const std::uint32_t m = mask_[J];
#pragma GCC unroll 8
      for (int a = 0; a < 8; ++a) {
        const int slot = base + std::popcount(m & kCellBlockTables.below[8 * a + b]);
        const int lo = a < b ? a : b, hi = a < b ? b : a;
        if (mass) mass[slot] += blocks.mass(lo, hi);
        if (stiffness) stiffness[slot] += blocks.stiffness(lo, hi);
      }
    }
  }
  /// Pieces of cell c: piece_order()[cell_start()[c] .. cell_start()[c+1]).
  const std::vector<int>& cell_start() const {
    return cell_start_;
  }
  const std::vector<int>& piece_order() const {
    return piece_order_;
  }
  /// The lock-free accumulation order (SetSystemMatrices), shared by the rebuilt assembly and the
  /// tracked update: the level's cells cut into tiles of kTileSide³ cells, tiles grouped by the
  /// parity colour (I%2)+2(J%2)+4(K%2) of their tile index. Tiles of one colour are a whole tile
  /// apart, so they share no function and are accumulated in parallel; the cells of one tile are
  /// accumulated serially in index order, so the result does not depend on the thread count.
  /// Why tiles and not a parity colour per cell: a tile's cells touch the same few hundred matrix
  /// rows, which stay in cache, while 8 passes of single-cell colours each swept both matrices.
  struct CellTiles {
    static constexpr int kTileSide = 8;
    std::vector<int>
        cells;  ///< cell indices, grouped by colour, then tile, ascending inside a tile
    std::vector<int> tile_start;        ///< tile t: cells[tile_start[t] .. tile_start[t+1])
    std::array<int, 9> colour_start{};  ///< colour q: tiles [colour_start[q], colour_start[q+1])
  };
  const CellTiles& tiles() const {
    return tiles_;
  }
  /// Runs `count = f(cells, n)` on every tile (its n cell indices in accumulation order) in the
  /// order above: 8 colour passes, the tiles of a pass in parallel. Returns the sum of the counts.
  template <class F>
  long long for_each_tile(F&& f) const {
    const CellTiles& T = tiles_;
    long long total = 0;
    for (std::size_t colour = 0; colour < 8; ++colour)
      total += tbb::parallel_reduce(
          tbb::blocked_range<int>(T.colour_start[colour], T.colour_start[colour + 1], 1), 0LL,
          [&](const tbb::blocked_range<int>& r, long long count) {
            for (int tile = r.begin(); tile != r.end(); ++tile) {
              const int first = T.tile_start[std::size_t(tile)];
              count += f(T.cells.data() + first, T.tile_start[std::size_t(tile) + 1] - first);
            }
            return count;
          },
          [](long long a, long long b) { return a + b; });
    return total;
  }
  const std::vector<int>& piece_cell() const {
    return piece_cell_;
  }

  /// For the tracked basis, once it holds its own compact copy of the pieces: frees what only
  /// assemble() reads — the pieces' cells and order. The pattern, the masks,
  /// the tiles and cell_start() stay, so add_cell_blocks() and view() still work; assemble()
  /// then throws.
  void release_pieces();
  bool pieces_released() const {
    return released_;
  }

  /// Mass and stiffness with the identity metric (the pieces' own geometry), any cubature rule.
  /// `mass` and `stiffness` become values on this system's pattern (see view()); accumulation is
  /// lock-free (tiles(): 8 colour passes, parallel over the tiles of a pass) and deterministic.
  void assemble(const CubatureRule& rule, std::vector<double>& mass,
                std::vector<double>& stiffness) const;

 private:
  const Octree* octree_;
  const std::vector<ClippedTriangle>* pieces_;
  int level_;
  std::vector<int> piece_cell_;
  std::vector<int> cell_start_, piece_order_;
  CellTiles tiles_;
  std::vector<std::uint32_t> mask_;
  std::vector<int> outer_, inner_;  // the pattern (no values stored: the bases keep M's and K's)
  bool released_ = false;
};

/// Finest-cell index of every piece (binary search, parallel). Throws if a piece's cell is
/// inactive.
std::vector<int> locate_pieces(const Octree& octree, const std::vector<ClippedTriangle>& pieces);

/// Builds the octree over the pieces' cells (cube.depth = finest depth).
Octree build_octree(const GridCube& cube, const std::vector<ClippedTriangle>& pieces,
                    int coarsest_depth);

/// P_l : level l -> l+1 (rows: fine functions, columns: coarse functions), coarsest first.
std::vector<SparseMatrix> build_prolongations(const Octree& octree);
/// Per level, per function: (i%2) + 2(j%2) + 4(k%2).
std::vector<std::vector<std::uint8_t>> build_colours(const Octree& octree);

/// The 8 functions and trilinear weights that evaluate a point (e.g. an original vertex).
struct PointStencil {
  std::array<int, 8> functions;
  std::array<double, 8> weights;
};
/// Stencils at the finest level; each point is evaluated in an active finest cell whose closed box
/// contains it (points on cell faces: the first active one of the candidate cells). Throws
/// std::runtime_error when no such cell is active (a point away from every piece).
std::vector<PointStencil> point_stencils(const Octree& octree, const Positions& points);
/// Stencil of a point in a given level-`level` cell (local coordinates clamped to the cell).
PointStencil cell_stencil(const Octree& octree, int level, int cell, const Eigen::Vector3d& p);

/// A mesh's vertices as an octree basis evaluates them. A vertex no face uses (files may have
/// them; `mesh-info` reports `unreferenced_vertices`) lies on no piece, so no active cell need
/// hold it: it keeps its position, as the hat basis keeps it.
struct VertexStencils {
  std::vector<PointStencil> used;  ///< stencils of the vertices some face uses, in vertex order
  std::vector<int> used_index;     ///< their vertex numbers; empty when every vertex is used
  Positions kept;  ///< every vertex's position at construction; empty when all are used
};
VertexStencils vertex_stencils(const Octree& octree, const Positions& vertices,
                               const Triangles& faces);
/// All vertices: the used ones evaluated from the coefficients, the others where they were.
Positions evaluate_vertices(const VertexStencils& stencils, const Coefficients& x);

}  // namespace mcf
