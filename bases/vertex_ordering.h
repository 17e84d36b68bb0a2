#pragma once
// A numbering of a mesh's vertices in which neighbours have nearby numbers: Cuthill–McKee
// (breadth-first from a pseudo-peripheral vertex, each vertex's unnumbered neighbours taken by
// increasing degree; George & Liu, "Computer Solution of Large Sparse Positive Definite Systems",
// 1981, Section 4.3). Its bandwidth on a surface mesh is about the widest breadth-first level, of
// the order of the square root of the vertex count, which is what lets the multigrid relax blocks
// of consecutive functions in parallel (solvers/multigrid.h, "Smoother ordering"): a mesh read
// from a file, or subdivided, numbers neighbours up to the whole mesh apart.
//
// Deterministic: ties are broken by vertex index. Components are numbered one after the other,
// each from its own start; vertices no face uses come last, in index order.

#include "datasets/mesh.h"

#include <vector>

namespace mcf {

/// order[k] = the vertex numbered k; a permutation of 0 .. vertex_count-1.
std::vector<int> bandwidth_ordering(const Triangles& faces, int vertex_count);

}  // namespace mcf
