#pragma once
// Reading and writing OFF, PLY (ASCII and binary), OBJ and STL through OpenMesh.

#include "datasets/mesh.h"
#include "datasets/mesh_error.h"

#include <string>

namespace mcf {

/// Reads a triangle mesh; the format follows the extension. Throws MeshError naming the file on a
/// missing/unreadable file, a parse error, non-triangle faces that cannot be triangulated, or
/// faces OpenMesh dropped (non-manifold "complex edges": the face count read is compared with
/// the file's). Vertex order of the file is kept. Does not validate geometry: see validate_mesh.
TriangleMesh read_mesh(const std::string& path);

/// Writes a mesh; format from the extension (.off .ply .obj .stl); binary where the format has
/// it and binary=true (PLY, STL; OFF and OBJ are always ASCII). OFF and OBJ keep doubles exactly
/// (17 digits); PLY and STL go through OpenMesh and store float coordinates. Faces OpenMesh could not
/// represent (non-manifold) are an error rather than silently dropped. Atomic: written to a temporary file in the same folder, then renamed.
void write_mesh(const std::string& path, const TriangleMesh& mesh, bool binary = true);

}  // namespace mcf
