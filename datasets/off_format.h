#pragma once
// The OFF format read in exact doubles: ASCII (Geomview's [ST][C][N][4][n]OFF prefixes) and binary
// OFF in the layout OpenMesh reads and writes. Written by mesh_io (datasets/mesh_io.h), whose
// ASCII bodies are OFF's lines.

#include "datasets/walked_mesh.h"

#include <string>

namespace mcf {

/// Walks the whole file, ASCII or binary (a header line "... OFF BINARY"): every vertex, and each
/// face's corner indices (faces fan-triangulated, `source` their record number). Throws MeshError
/// naming the file and the line (ASCII) or the vertex or face and its byte (binary) on a bad
/// header, a count beyond the mesh's int indices, a non-finite or homogeneous-zero coordinate, a
/// face with fewer than 3 corners or an index outside the vertices, or a file that ends early.
WalkedMesh scan_off(const std::string& path);

}  // namespace mcf
