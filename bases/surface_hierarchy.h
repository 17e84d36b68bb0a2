#pragma once
// A multigrid hierarchy for the hat basis, built once from the input mesh: sampled coarse levels
// with barycentric prolongation, after Wiersma, Nasikun, Eisemann & Hildebrandt, "A Fast Geometric
// Multigrid Method for Curved Surfaces" (SIGGRAPH 2023), Section 4.
//
// One coarsening step, on a level given as points, a vertex graph and triangles:
//   1. Samples: a maximal independent set of the graph, chosen greedily in index order (every
//      vertex is a sample or a neighbour of one; on a triangle mesh about one vertex in four to
//      five is kept).
//   2. Each vertex joins the cell of its nearest sample by graph distance along the edges
//      (multi-source Dijkstra; ties go to the smaller sample index), a graph Voronoi diagram.
//   3. The coarse level's vertices are the samples (at their own positions, numbered in the fine
//      level's order), its edges join cells that a fine edge joins, and its triangles are the fine
//      triangles whose three corners lie in three different cells (the Voronoi diagram's dual).
//   4. Prolongation: a sample takes its coarse vertex's value; any other vertex is projected onto
//      the plane of each coarse triangle around its cell's sample and takes the barycentric
//      combination of the triangle it lies most inside (largest smallest coordinate), negative
//      coordinates clamped to zero and the rest renormalized. Rows sum to one, so constants are
//      reproduced exactly; a linear function is reproduced at every vertex that lies inside one of
//      those triangles (all of them on a flat mesh, away from the boundary). A cell whose sample
//      has no coarse triangle falls back to the sample's value.
// Levels are coarsened until one has at most `coarsest_size` vertices (the multigrid solves it
// directly) or coarsening stops shrinking.
//
// Each level also gets a Gauss-Seidel colouring of the pattern its Galerkin matrix will have
// (the finest: vertices sharing a triangle; coarser: P^T A P's, core/galerkin_pattern.h),
// smallest-last greedy, so that the multigrid can relax colour by colour in parallel; a level that
// needs more than the eight colours the solver takes gets no colouring and is relaxed in blocks of
// consecutive rows (solvers/multigrid.h, "Smoother ordering").
//
// Everything is deterministic: serial loops in fixed orders, ties broken by index, and parallel
// loops whose iterations write disjoint outputs, over fixed chunks where they gather (the same
// hierarchy for any thread count).

#include "core/sparse.h"
#include "datasets/mesh.h"

#include <cstdint>
#include <vector>

namespace mcf {

struct SurfaceHierarchyOptions {
  int coarsest_size = 1000;  ///< stop once a level has at most this many vertices
  int max_levels = 16;       ///< levels in all, the finest included
};

struct SurfaceHierarchy {
  /// prolongations[l] maps level l to level l + 1 (coarsest first), rows x columns = the finer
  /// level's size x the coarser level's.
  std::vector<SparseMatrix> prolongations;
  /// Per level, coarsest first, the finest last: colours in 0..7, or empty for a level relaxed
  /// serially.
  std::vector<std::vector<std::uint8_t>> colours;
  /// Per level, coarsest first: its points (the samples' positions; the mesh's on the finest).
  std::vector<Positions> points;
  int levels() const { return int(colours.size()); }
};

/// The hierarchy of a triangle mesh (vertices unreferenced by any face form cells of their own
/// and are kept on every level with the identity prolongation).
SurfaceHierarchy build_surface_hierarchy(const Positions& vertices, const Triangles& faces,
                                         const SurfaceHierarchyOptions& options = {});

/// Graph Voronoi cells (header, step 2): for a graph in compressed rows (neighbours of v in
/// neighbour[start[v] .. start[v+1]), symmetric, no self loops) with edge lengths |p_v - p_w|
/// between its points, and sample[v] >= 0 the index of the sample at v (-1 elsewhere): per vertex,
/// the index of the nearest sample by graph distance, ties to the smaller index
/// (std::numeric_limits<int>::max() where no sample is reached). Exactly the labels of a
/// multi-source Dijkstra that orders (distance, index) lexicographically, computed by parallel
/// sweeps (deterministic) and checked to be those; where the check cannot tell (an edge too short
/// to add to a distance, e.g. between coincident points) or the sweeps do not settle within 64
/// (cells many edges wide), by that Dijkstra.
std::vector<int> graph_voronoi_cells(const std::vector<int>& start,
                                     const std::vector<int>& neighbour, const Positions& points,
                                     const std::vector<int>& sample);

/// A smallest-last greedy colouring of a symmetric pattern (the pattern's diagonal is ignored):
/// colours[i] differs from the colour of every j with A(i, j) stored, j != i. Returns the colours;
/// `count` receives the number used.
std::vector<int> greedy_colouring(const SparseMatrix& pattern, int* count = nullptr);

}  // namespace mcf
