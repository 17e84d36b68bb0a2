#pragma once
// The STL format, ASCII and binary, read through OpenMesh in the layout decided here (not by
// OpenMesh's guess from the file's length) after a streaming pass that checks its lines; what
// OpenMesh dropped or duplicated is found by counts. Written by mesh_io (datasets/mesh_io.h),
// through OpenMesh.

#include "datasets/mesh.h"

#include <string>

namespace mcf {

/// Reads the file, merging equal corners into vertices. Throws MeshError naming the file, and the
/// line of an ASCII file, on a line OpenMesh would misread, bytes after a binary file's triangles
/// that could be triangles, a file too short for its count, or faces OpenMesh could not add
/// (non-manifold edges or vertices, repeated corners, inconsistent orientation).
TriangleMesh read_stl(const std::string& path);

}  // namespace mcf
