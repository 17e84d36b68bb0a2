#pragma once
// Reading and writing OFF, PLY (ASCII and binary), OBJ and STL. OpenMesh reads every format
// (its half-edge insertion finds non-manifold faces); our own scans of OFF, OBJ and PLY check
// the file against it and supply exact doubles; OFF, OBJ and PLY are written here, STL by OpenMesh.

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
/// it and binary=true (PLY, STL; OFF and OBJ are always ASCII). OFF, OBJ and PLY keep doubles
/// exactly (17 digits in text, `property double` in PLY); STL, whose format has only floats,
/// goes through OpenMesh. Faces OpenMesh could not
/// represent (non-manifold) are an error rather than silently dropped. Atomic: written to a temporary file in the same folder, then renamed.
void write_mesh(const std::string& path, const TriangleMesh& mesh, bool binary = true);

}  // namespace mcf
