#pragma once
// What a walk of an OFF, OBJ or PLY file found, before any topology is built: the coordinates as
// exact doubles and every face fan-triangulated, in file order, with where each triangle came
// from so that errors found later (mesh_io's half-edge check) can name the file's own face.

#include <cstddef>
#include <vector>

namespace mcf {

struct WalkedMesh {
  std::vector<double> coords;     ///< x, y, z per vertex, as stored (float widened exactly)
  std::vector<int> triangles;     ///< 3 vertex indices (0-based) per triangle
  std::vector<long long> source;  ///< per triangle: the file's face (0-based record), or its line
  bool source_is_line = false;    ///< OBJ: `source` holds line numbers
  int index_base = 0;             ///< how the file numbers its vertices (OBJ: from 1)
};

/// Appends one face's fan (corners c0 c1 ... ck-1: triangles c0 ci ci+1, as OpenMesh's TriMesh
/// triangulates a polygon), each triangle recorded as coming from `source`.
inline void add_fan(WalkedMesh& walk, const std::vector<int>& corner, long long source) {
  for (std::size_t j = 1; j + 1 < corner.size(); ++j) {
    walk.triangles.insert(walk.triangles.end(), {corner[0], corner[j], corner[j + 1]});
    walk.source.push_back(source);
  }
}

}  // namespace mcf
