#pragma once
// The opt-in repair of zero-area faces (flow config key repair_degenerate, `--repair-degenerate`):
// the hat basis needs every face's cotangents, which a zero-area face does not have, and a mesh
// whose user chose to go on without those faces gets them collapsed instead of refused.

#include "datasets/mesh.h"

namespace mcf {

struct CollapseReport {
  long long degenerate_faces = 0;  ///< zero-area faces (degenerate_faces) collapsed and removed
  long long removed_faces = 0;     ///< faces gone in all (those and their neighbours across the
                                   ///< collapsed edges)
  long long merged_vertices = 0;   ///< vertices merged into a neighbour (left unreferenced)
};

/// Collapses every degenerate face (validate.h's degenerate_faces) into an edge or a point: its
/// shortest edge is contracted, the vertex of that edge that lies between the other two (for a
/// flat "cap") or the larger index (for coincident corners) merged into the other, so the
/// surface's shape moves by at most the length of a zero-area face's shortest edge. Faces left
/// with a repeated corner are dropped; repeated until no degenerate face is left. Vertices are
/// kept (a merged one stays, unreferenced, where it was), so vertex indices and order hold;
/// the faces left keep their order. The result may be non-manifold where a collapse pinched the
/// surface (the caller checks it as any mesh).
CollapseReport collapse_degenerate_faces(TriangleMesh& mesh);

}  // namespace mcf
