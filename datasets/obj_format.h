#pragma once
// The OBJ format's geometry read in exact doubles: `v` and `f` records (texture coordinates and
// normals ignored). Written by mesh_io (datasets/mesh_io.h).

#include "datasets/walked_mesh.h"

#include <string>

namespace mcf {

/// Walks the whole file: every `v` record, and each `f` record's corners (faces fan-triangulated,
/// `source` their line; vertices numbered from 1, negative indices counting back). Throws
/// MeshError naming the file and the line on a bad record, a non-finite coordinate, a face with
/// fewer than 3 corners or an index outside the vertices, or counts beyond the mesh's int indices.
WalkedMesh scan_obj(const std::string& path);

}  // namespace mcf
