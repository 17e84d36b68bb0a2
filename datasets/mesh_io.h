#pragma once
// Reading and writing OFF, PLY (ASCII and binary), OBJ and STL. OFF (binary OFF read only), OBJ
// and PLY are read and written by our own code, in exact doubles; STL through OpenMesh. Every mesh
// read, and every mesh written unless the caller vouches for its faces (FaceCheck), is added face
// by face to an OpenMesh half-edge mesh, whose insertion finds non-manifold edges and vertices
// and inconsistently oriented faces.

#include "datasets/mesh.h"
#include "datasets/mesh_error.h"

#include <string>

namespace mcf {

/// What read_mesh changed of the file's faces.
struct ReadReport {
  /// Faces whose corner order was reversed so that every face agrees with its neighbours
  /// (datasets/orientation.h); 0 for a consistently oriented file.
  long long reoriented_faces = 0;
};

/// Reads a triangle mesh; the format follows the extension; polygons are fan-triangulated from
/// their first corner. OFF, OBJ and PLY faces listed with mixed orientation are oriented
/// consistently (orient_faces; how many were reversed goes to `report`). Throws MeshError naming
/// the file, and where it can the line, byte or face, on a missing/unreadable file, a parse error,
/// a face repeating a vertex, an edge in three or more faces (non-manifold), a non-orientable
/// surface, or a face a half-edge mesh cannot hold (naming the first such face, its vertices as
/// the file numbers them, and why). Vertex and face order of the file are kept. Does not validate
/// geometry: see validate_mesh.
TriangleMesh read_mesh(const std::string& path, ReadReport* report = nullptr);

/// Adds the faces to an OpenMesh half-edge mesh, as read_mesh and write_mesh do, and throws
/// MeshError naming `name` and the first face it cannot hold, and why. load_mesh_spec runs it on
/// generated meshes (read_mesh has run it on files), so a MeshSource's faces may be written with
/// FaceCheck::trusted.
void check_half_edge_faces(const TriangleMesh& mesh, const std::string& name);

/// What read_mesh does to a file's faces, for a mesh in memory (faces and vertices named by their
/// 0-based indices): checks every face's corners (in range, three different ones), orients the
/// faces consistently (orient_faces) and adds them to a half-edge mesh. Returns how many faces
/// were reversed; throws MeshError naming `name` and the first face it cannot take, and why.
long long orient_and_check_faces(TriangleMesh& mesh, const std::string& name);

/// What write_mesh checks of the faces before it writes.
enum class FaceCheck {
  /// Every face is added to a half-edge mesh, as on reading: a face it cannot hold (non-manifold
  /// edge or vertex, inconsistent orientation, a repeated or out-of-range corner) is an error, so
  /// every file written reads back.
  half_edge,
  /// The caller vouches that the faces passed that check already: a flow writing its frames and
  /// final mesh with the faces of a MeshSource (checked by load_mesh_spec), which no flow
  /// changes. Building the half-edge mesh again would be most of the cost of writing a frame.
  /// STL, which OpenMesh writes from a half-edge mesh, is checked anyway.
  trusted,
};

/// Writes a mesh; format from the extension (.off .ply .obj .stl); binary where the format has
/// it and binary=true (PLY, STL; OFF and OBJ are always ASCII). OFF, OBJ and PLY keep doubles
/// exactly (17 digits in text, `property double` in PLY); STL, whose format has only floats,
/// goes through OpenMesh. A face a half-edge mesh cannot hold (non-manifold) is an error, as on
/// reading, rather than silently dropped (unless `check` is FaceCheck::trusted). Atomic: written
/// to a temporary file in the same folder, then renamed.
void write_mesh(const std::string& path, const TriangleMesh& mesh, bool binary = true,
                FaceCheck check = FaceCheck::half_edge);

}  // namespace mcf
