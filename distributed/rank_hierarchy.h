#pragma once
// The surface multigrid's hierarchy across ranks, built per partition: each rank coarsens the
// surface of the vertices it owns (the triangles whose three corners it owns) with the
// one-process hierarchy's sampling and barycentric prolongation (bases/surface_hierarchy.h), so
// that its coarse vertices, like its fine ones, are its own and the global prolongation is block
// diagonal across ranks: no rank needs another's mesh to build it, and the Galerkin coarse
// operators P^T A P (formed by PETSc) couple the partitions through A's off-rank entries. Ranks
// may coarsen to different depths; all keep the finest `levels` levels that every rank has, so the
// coarsest level is the union of the ranks' coarsest ones (solved redundantly on every rank).

#include "core/sparse.h"
#include "distributed/rank_mesh.h"

#include <vector>

namespace mcf::dist {

struct RankHierarchy {
  /// prolongations[l] maps this rank's part of level l to its part of level l + 1 (coarsest
  /// first; rows: level l + 1's vertices on this rank, the finest being the owned vertices in
  /// local order; columns: level l's).
  std::vector<SparseMatrix> prolongations;
  int levels() const { return int(prolongations.size()) + 1; }
};

/// Collective (the ranks agree on the number of levels). `coarsest_size`: a rank stops
/// coarsening its part at this many vertices.
RankHierarchy build_rank_hierarchy(const RankMesh& mesh, int coarsest_size);

}  // namespace mcf::dist
