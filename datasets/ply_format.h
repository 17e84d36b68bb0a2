#pragma once
// The PLY format (ASCII, binary little- and big-endian) read and written in double precision.
//
// Why not OpenMesh's reader: it goes through floats and, on a truncated file, an out-of-range
// index or a NaN, drops faces or duplicates vertices without an error, which read_mesh could then
// only blame on non-manifold input; its writer stores float coordinates, so a flow's final.ply
// and frames lost the last 29 bits of every coordinate. mesh_io builds the mesh from this walk
// and adds its faces to an OpenMesh half-edge mesh, whose insertion finds non-manifold faces.

#include "datasets/mesh.h"
#include "datasets/walked_mesh.h"

#include <cstdio>
#include <string>
#include <vector>

namespace mcf {

/// Walks the whole file: header, every element's records, each face's corner indices (faces
/// fan-triangulated, `source` their record number). Throws
/// MeshError naming the file and the line (ASCII, header) or byte offset (binary body) on an
/// unknown format or type, a missing x/y/z or vertex_indices property, a non-finite coordinate, a
/// face with fewer than 3 corners, an index outside 0..vertices-1, or a file that ends early (or
/// more than 2^31 - 1 vertices or triangles, beyond the mesh's int indices).
WalkedMesh scan_ply(const std::string& path);

/// The header of a PLY file of this mesh with `property double x, y, z` and faces as `list uchar
/// int vertex_indices`; ASCII bodies (17 significant digits, one record a line) are written by
/// mesh_io beside OFF's, whose lines are the same, binary ones by write_ply_binary_body.
std::string ply_header(const TriangleMesh& mesh, bool binary);

/// The body of a binary little-endian PLY file under ply_header(mesh, true): every coordinate
/// reads back exactly.
void write_ply_binary_body(std::FILE* out, const TriangleMesh& mesh);

}  // namespace mcf
