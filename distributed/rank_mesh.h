#pragma once
// One rank's piece of a mesh divided across MPI ranks (docs/petsc.md, "Across MPI ranks").
//
// Ownership is by vertex. The vertices are partitioned into one part per rank (PT-Scotch through
// PETSc's MatPartitioning, on the vertex graph), and numbered globally part after part, each part
// in the bandwidth ordering of the whole mesh (bases/vertex_ordering.h: the order the smoothers'
// Gauss-Seidel sweeps then go, which took the distributed multigrid on the 832k-face armadillo
// from 42-47 to 24-28 V(2,2)-cycles to 1e-10), so that rank r owns the contiguous global rows
// [first, first + owned) —
// PETSc's row ownership of a distributed matrix. A rank keeps every triangle with at least one
// vertex it owns, and the other vertices of those triangles as ghosts: one ring, which is all the
// hat basis needs, since each of its M's and K's entries in an owned row is a sum over the
// triangles around the owned vertex (bases/hat_basis.h). Local numbering: the owned vertices
// first (local i is global first + i), then the ghosts in increasing global order.
//
// Each triangle is *counted* (in area, moments and other sums over the surface) by exactly one
// rank: the owner of its smallest global vertex. So a sum over the surface is the ordered sum
// (distributed/comm.h) of the ranks' sums over their counted triangles.
//
// Rank 0 reads or generates the whole mesh and partitions it, sends each rank its piece and keeps
// of the whole only what the output needs: the faces (12 bytes a face) and the input index of
// every global vertex (8 bytes a vertex). Every other rank holds its piece only.

#include "datasets/mesh.h"

#include <cstdint>
#include <string>
#include <vector>

namespace mcf::dist {

struct RankMesh {
  int rank = 0, ranks = 1;
  std::int64_t global_vertices = 0, global_faces = 0;
  /// Global number of the first owned vertex; the owned ones are [first, first + owned).
  std::int64_t first = 0;
  int owned = 0;
  /// Per rank, its first global vertex; first_of[ranks] = global_vertices.
  std::vector<std::int64_t> first_of;
  /// Local vertex owned + k is the ghost of global number ghost_global[k] (increasing), owned by
  /// rank ghost_owner[k].
  std::vector<std::int64_t> ghost_global;
  std::vector<int> ghost_owner;
  /// Per owned vertex, its index in the input mesh (the order of every file written).
  std::vector<std::int64_t> input_index;
  /// owned + ghosts rows: positions at the start (owned first).
  Positions vertices;
  /// Every triangle with an owned vertex, on local numbers, in the input's order.
  Triangles faces;
  /// Per local triangle: whether this rank counts it (it owns its smallest global vertex).
  std::vector<char> counted;
  /// How the vertices were partitioned ("ptscotch", or "blocks of the bandwidth ordering" where
  /// the partitioner left a part empty).
  std::string partitioner;

  int ghosts() const { return int(ghost_global.size()); }
  int local_vertices() const { return owned + ghosts(); }
  /// The global number of local vertex i.
  std::int64_t global(int i) const {
    return i < owned ? first + i : ghost_global[std::size_t(i - owned)];
  }
};

/// What rank 0 keeps of the whole mesh for the output: the faces on input indices, and per global
/// vertex its input index. Empty on the other ranks.
struct OutputMap {
  Triangles faces;
  std::vector<std::int64_t> input_of_global;
};

/// One part (0 .. parts-1) per vertex: PT-Scotch's partition of the vertex graph (vertices
/// joined by an edge), or, where it leaves a part empty (a mesh of few vertices) or PETSc has no
/// PT-Scotch, consecutive blocks of the bandwidth ordering (bases/vertex_ordering.h). `method`
/// receives which. Deterministic.
std::vector<int> partition_vertices(const Triangles& faces, int vertex_count, int parts,
                                    std::string* method = nullptr);

/// Collective: rank 0 passes the whole mesh (the others an empty one), partitions it and sends
/// every rank its piece. Returns this rank's piece; on rank 0 `output` receives what it keeps for
/// the output. With one rank the piece is the whole mesh (no ghosts).
RankMesh scatter_mesh(const TriangleMesh& whole, OutputMap* output = nullptr);

}  // namespace mcf::dist
