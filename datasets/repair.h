#pragma once
// The opt-in repair of zero-area faces (flow config key repair_degenerate, `--repair-degenerate`):
// the hat basis needs every face's cotangents, which a zero-area face does not have, and a mesh
// whose user chose to go on without those faces gets them removed instead of refused.

#include "datasets/mesh.h"

namespace mcf {

struct DegenerateRepair {
  long long degenerate_faces = 0;  ///< zero-area faces (degenerate_faces) removed, by either way
  long long flipped_faces = 0;     ///< of those, flat caps removed by an edge flip
  long long removed_faces = 0;     ///< faces gone from the mesh (collapsed ones and their
                                   ///< neighbours across the collapsed edges)
  long long merged_vertices = 0;   ///< vertices merged into a neighbour (left unreferenced)
};

/// Removes every degenerate face (validate.h's degenerate_faces), until none is left:
/// - a flat "cap" (three distinct corners on a line) whose longest edge has a face on its other
///   side is flipped away: the cap (a, b, c), b between a and c, and that face (a, c, d) become
///   (a, b, d) and (b, c, d), which split the face at b. No vertex moves and no face goes; done
///   only where both new faces have area and the edge (b, d) is new.
/// - any other is collapsed: its shortest edge is contracted, the corner of that edge lying
///   between the other two (or, for coincident corners, the larger index) merged into the other,
///   so the surface moves by at most that edge's length; faces left with a repeated corner go.
/// Vertices are kept (a merged one stays, unreferenced, where it was), so vertex indices and
/// order hold; faces keep their order. Orientation is kept. The result may be non-manifold where
/// a collapse pinched the surface (the caller checks it as any mesh).
DegenerateRepair repair_degenerate_faces(TriangleMesh& mesh);

}  // namespace mcf
