#pragma once
// The multigrid solver's internal numbering of a level (header solvers/multigrid.h, "Internal
// numbering" and "Smoother ordering"): the permutation from the level's given parity colours to
// tile-wise colour-major order, the check that the colouring is valid, the relaxation blocks, the
// order in which a sweep visits the rows, and the permutation of matrices into and out of the
// internal numbering.
//
// Inputs: a level's size, its given colours (one of 0..7 per function, or none) and its matrix
// pattern in the internal numbering. Outputs: LevelNumbering and permuted copies of matrices. All
// of it is deterministic: the permutations depend on the colours alone, the checks are logical
// reductions, and the parallel loops write disjoint entries.
//
// Internal to the multigrid solver (namespace multigrid_detail); not part of the solvers'
// interface.

#include "core/sparse.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace mcf::multigrid_detail {

// ---- the solver's internal numbering -------------------------------------------------------
//
// Each coloured level is stored in tiles of kTile consecutive caller indices, colour-major inside
// each tile (colour 0's functions of the tile first, each colour in index order). A colour pass of
// Gauss-Seidel then streams one contiguous segment per tile instead of every eighth row of the
// whole matrix (interleaved rows defeat the hardware prefetchers), and the rows a coarse
// function's support touches stay within a few tiles, which keeps the Galerkin product's
// accumulators in cache (a global colour-major order does not; docs/benchmarks.md, "Measurements
// behind implementation choices"). The parity
// 8-colour ordering and its iterates are unchanged. `perm[r]` is the caller's index of internal
// row r, `inv` its inverse; both are empty for the identity.

constexpr int kTile = 1024;        // MultigridSolver::tile_size (multigrid.cpp asserts they agree)
constexpr int kMinBlockTiles = 8;  // tiles per relaxation block, at least (find_blocks())

inline int old_index(const std::vector<int>& perm, int r) {
  return perm.empty() ? r : perm[std::size_t(r)];
}
inline int new_index(const std::vector<int>& inv, int i) {
  return inv.empty() ? i : inv[std::size_t(i)];
}

/// M with entry (i, j) moved to (row_inv[i], col_inv[j]) (col_perm = inverse of col_inv). With
/// `sort` each column is sorted by its new row indices; without, the entries of each column keep
/// their relative order (so a row sum visits its terms in the caller's order).
SparseMatrix permuted(const SparseRef& Mm, const std::vector<int>& row_inv,
                      const std::vector<int>& col_perm, bool sort);

/// Whether `stored` == permuted(given, row_inv, col_perm, sort) (pattern, and values when asked)
/// without building the permuted copy. Unsorted, with diag_rank (the finest level): column r
/// stores the caller's diag_rank[r]-th entry last (diagonal_last, solvers/smoother.h).
bool same_permuted(const SparseMatrix& stored, const SparseRef& given,
                   const std::vector<int>& row_inv, const std::vector<int>& col_perm, bool sort,
                   bool values, const std::vector<int>& diag_rank = {});

/// A level's internal numbering and its relaxation blocks.
struct LevelNumbering {
  std::vector<int> perm, inv;  // internal row r <-> caller's index perm[r]; empty: identity
  bool coloured = false;
  std::vector<int> segment_start;  // rows of colour c in tile t: [s[8t+c], s[8t+c+1])
  int block_tiles = 1;             // tiles per relaxation block (find_blocks())
  /// A level without a valid colouring: rows per relaxation block (find_blocks()), of n rows.
  int block_rows = 1, rows = 0;
  int tiles() const { return int(segment_start.size() / 8); }
  int blocks() const {
    return coloured ? (tiles() + block_tiles - 1) / block_tiles
                    : (rows + block_rows - 1) / block_rows;
  }
  /// The internal rows [first, last) of relaxation block q of a level without colours.
  int block_first(int q) const { return q * block_rows; }
  int block_last(int q) const { return std::min(rows, (q + 1) * block_rows); }
};

/// The level's internal numbering from its given colours: blocks of kTile consecutive caller
/// indices, colour-major inside each block (identity when no colours are given, their count is
/// wrong or a colour is out of 0..7). Segment (t, c) = rows of colour c in block t.
void number_by_colour(LevelNumbering& L, int n, const std::vector<std::uint8_t>* given);

/// A numbered level is coloured when no two functions of one colour couple (checked on the
/// level's matrix pattern A, in the internal numbering, with its given colours); otherwise it is
/// relaxed in blocks of rows of its internal order (find_blocks()).
void check_colouring(LevelNumbering& L, const SparseMatrix& A,
                     const std::vector<std::uint8_t>* given);

/// Relaxation blocks (header, "Smoother ordering"). A coloured level: runs of `block_tiles`
/// consecutive tiles, at least as many as the farthest coupling reaches (in tiles), so rows of
/// block q couple only with blocks q-1, q, q+1 and blocks of one parity never couple.
/// A block's rows and iterates stay in cache through its eight colours (on the armadillo at
/// depth 9 the farthest coupling reaches 9 tiles). A floor of kMinBlockTiles (8) instead of 1
/// costs nothing measurable there and keeps small levels from being cut into many tiny tasks.
/// A level without colours: runs of `block_rows` consecutive rows, at least the farthest coupling
/// (in rows) and at least kMinBlockTiles tiles' worth, for the same reason; a level whose
/// couplings reach across half of it has at most two blocks, whose order is plain 0..n-1.
/// A is the level's matrix in the internal numbering.
void find_blocks(LevelNumbering& L, const SparseMatrix& A);

// The relaxation order (header, "Smoother ordering") in one place, for the sweep
// (gauss_seidel_sweep, solvers/smoother.h) and relaxation_order(): a sweep is two passes, pass pi
// relaxing the blocks of parity block_parity(pi, reverse); block q is relaxed colour by colour,
// tiles ascending, and for_block_segments calls f(r0, r1) for each run of internal rows in that
// order.
inline int block_parity(int pi, bool reverse) {
  return reverse ? 1 - pi : pi;
}
template <class F>
void for_block_segments(const LevelNumbering& L, int q, bool reverse, F&& f) {
  const int t0 = q * L.block_tiles, t1 = std::min(L.tiles(), t0 + L.block_tiles);
  for (int ci = 0; ci < 8; ++ci) {
    const std::size_t c = std::size_t(reverse ? 7 - ci : ci);
    for (int t = t0; t < t1; ++t) {
      const std::size_t q8 = std::size_t(t) * 8 + c;
      f(L.segment_start[q8], L.segment_start[q8 + 1]);
    }
  }
}

/// The caller's indices of a level of n functions in the order a sweep (reverse or not) relaxes
/// them (serially).
std::vector<int> relaxation_order(const LevelNumbering& L, int n, bool reverse);

}  // namespace mcf::multigrid_detail
