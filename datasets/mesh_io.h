#pragma once
// Reading and writing OFF, PLY (ASCII and binary), OBJ and STL. OFF, OBJ and PLY are read and
// written by our own code, in exact doubles; STL (and binary OFF) through OpenMesh. Every mesh
// read or written is added face by face to an OpenMesh half-edge mesh, whose insertion finds
// non-manifold edges and vertices and inconsistently oriented faces.

#include "datasets/mesh.h"
#include "datasets/mesh_error.h"

#include <string>

namespace mcf {

/// Reads a triangle mesh; the format follows the extension; polygons are fan-triangulated from
/// their first corner. Throws MeshError naming the file, and where it can the line, byte or face,
/// on a missing/unreadable file, a parse error, a face repeating a vertex, or a face a half-edge
/// mesh cannot hold (naming the first such face, its vertices as the file numbers them, and
/// why). Vertex and face order of the file are kept. Does not validate geometry: see
/// validate_mesh.
TriangleMesh read_mesh(const std::string& path);

/// Writes a mesh; format from the extension (.off .ply .obj .stl); binary where the format has
/// it and binary=true (PLY, STL; OFF and OBJ are always ASCII). OFF, OBJ and PLY keep doubles
/// exactly (17 digits in text, `property double` in PLY); STL, whose format has only floats,
/// goes through OpenMesh. A face a half-edge mesh cannot hold (non-manifold) is an error, as on
/// reading, rather than silently dropped. Atomic: written to a temporary file in the same
/// folder, then renamed.
void write_mesh(const std::string& path, const TriangleMesh& mesh, bool binary = true);

}  // namespace mcf
