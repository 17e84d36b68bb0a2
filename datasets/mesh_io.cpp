// Mesh file I/O: read_mesh dispatches on the extension to one reader per format (off_format.h,
// obj_format.h, ply_format.h, stl_format.h). OFF, OBJ and PLY are walked once, in exact doubles,
// with errors that name the line; OpenMesh's half-edge insertion then checks the topology here,
// which its own readers would instead repair silently by dropping faces or duplicating vertices
// (docs/flow.md "Formats"). STL is read by OpenMesh (stl_format.cpp). write_mesh writes OFF, OBJ
// and PLY itself, in exact doubles, and STL through OpenMesh.

#include "datasets/mesh_io.h"

#include "core/atomic_file.h"
#include "datasets/obj_format.h"
#include "datasets/off_format.h"
#include "datasets/openmesh_mesh.h"
#include "datasets/orientation.h"
#include "datasets/ply_format.h"
#include "datasets/stl_format.h"
#include "datasets/walk_helpers.h"
#include "datasets/walked_mesh.h"

#include <OpenMesh/Core/IO/MeshIO.hh>

#include <unistd.h>
#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace mcf {
namespace {

namespace fs = std::filesystem;
using namespace walk_detail;
using namespace openmesh_detail;

std::string lower_extension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return ext;
}

// Face f's corners are vertices of the mesh, three different ones; else throws naming the face.
void check_corners(const std::string& path, const std::string& prefix, const TriangleMesh& mesh,
                   Eigen::Index f, const std::function<std::string(Eigen::Index)>& name_face,
                   const std::function<std::string(int)>& name_vertex) {
  const Eigen::Index nv = mesh.num_vertices();
  const int a = mesh.faces(f, 0), b = mesh.faces(f, 1), c = mesh.faces(f, 2);
  for (int v : {a, b, c})
    if (v < 0 || v >= nv)
      fail(path, prefix + name_face(f) + " references vertex " + std::to_string(v) +
                     " but the mesh has " + std::to_string(nv) + " vertices");
  // OpenMesh's add_face does not expect a repeated corner (its readers skip such faces).
  if (a == b || b == c || c == a)
    fail(path, prefix + name_face(f) + " repeats vertex " + name_vertex(a == b || a == c ? a : b) +
                   " (a degenerate face)");
}

// Orients the faces consistently (datasets/orientation.h) before the half-edge mesh is built, so
// that a manifold surface listed with mixed orientation loads; what cannot be oriented is an error
// naming the faces and the edge, and whether the mesh is non-manifold or non-orientable. Returns
// how many faces were reversed.
long long orient_or_fail(const std::string& path, TriangleMesh& mesh,
                         const std::function<std::string(Eigen::Index)>& name_face,
                         const std::function<std::string(int)>& name_vertex) {
  for (Eigen::Index f = 0; f < mesh.num_faces(); ++f)
    check_corners(path, "", mesh, f, name_face, name_vertex);
  const OrientationResult o = orient_faces(mesh.faces);
  auto face_with_corners = [&](Eigen::Index f) {
    return name_face(f) + " (vertices " + name_vertex(mesh.faces(f, 0)) + ", " +
           name_vertex(mesh.faces(f, 1)) + ", " + name_vertex(mesh.faces(f, 2)) + ")";
  };
  const std::string edge = "(" + name_vertex(o.edge[0]) + ", " + name_vertex(o.edge[1]) + ")";
  switch (o.problem) {
    case OrientationResult::Problem::none:
      return o.reoriented;
    case OrientationResult::Problem::non_manifold_edge:
      fail(path, "non-manifold mesh: " + face_with_corners(o.faces[2]) +
                     " cannot be added: its edge " + edge + " already has a face on each side (" +
                     name_face(o.faces[0]) + " and " + name_face(o.faces[1]) +
                     "): an edge in three or more faces is non-manifold");
    case OrientationResult::Problem::non_orientable:
      fail(path, "non-orientable mesh: " + face_with_corners(o.faces[1]) +
                     " cannot be oriented to agree with both its neighbours (reached across edge " +
                     edge + " from " + name_face(o.faces[0]) +
                     "): the surface is one-sided, like a Möbius strip, so no consistent "
                     "orientation of its faces exists");
  }
  return o.reoriented;
}

// Adds the faces to an OpenMesh half-edge mesh in order, as its readers do. A face it cannot add
// means a non-manifold ("complex") edge or vertex, or inconsistently oriented faces: the error
// names the first such face (name_face(f)) and why, after prefix. The half-edge mesh is
// returned for the STL writer.
IoMesh half_edge_mesh(const std::string& path, const std::string& prefix, const TriangleMesh& mesh,
                      const std::function<std::string(Eigen::Index)>& name_face,
                      const std::function<std::string(int)>& name_vertex) {
  const Eigen::Index nv = mesh.num_vertices(), nf = mesh.num_faces();
  IoMesh om;
  om.reserve(nv, nf + nv + 2, nf);  // edges: nf + nv - χ for a closed mesh
  std::vector<IoMesh::VertexHandle> vh(nv);
  for (Eigen::Index i = 0; i < nv; ++i)
    vh[i] =
        om.add_vertex(IoMesh::Point(mesh.vertices(i, 0), mesh.vertices(i, 1), mesh.vertices(i, 2)));
  for (Eigen::Index f = 0; f < nf; ++f) {
    check_corners(path, prefix, mesh, f, name_face, name_vertex);
    const int a = mesh.faces(f, 0), b = mesh.faces(f, 1), c = mesh.faces(f, 2);
    if (om.add_face(vh[a], vh[b], vh[c]).is_valid()) continue;
    // Why OpenMesh refused it, from the half-edge structure as it stood (a failed add_face
    // changes nothing).
    std::string why;
    const int corner[3] = {a, b, c};
    for (int j = 0; j < 3 && why.empty(); ++j) {
      const auto h = om.find_halfedge(vh[corner[j]], vh[corner[(j + 1) % 3]]);
      if (h.is_valid() && !om.is_boundary(h))
        why = "its edge (" + name_vertex(corner[j]) + ", " + name_vertex(corner[(j + 1) % 3]) +
              ") already has a face on the same side: the edge is in more than two faces, or the "
              "faces "
              "around it are inconsistently oriented";
    }
    for (int j = 0; j < 3 && why.empty(); ++j)
      if (!om.is_boundary(vh[corner[j]]))
        why = "its vertex " + name_vertex(corner[j]) +
              " is already surrounded by a closed fan of faces";
    if (why.empty())
      why = "its faces around a vertex cannot be ordered into one fan (a non-manifold vertex)";
    fail(path, prefix + "non-manifold mesh: " + name_face(f) + " (vertices " + name_vertex(a) +
                   ", " + name_vertex(b) + ", " + name_vertex(c) + ") cannot be added: " + why);
  }
  return om;
}

}  // namespace

TriangleMesh read_mesh(const std::string& path, ReadReport* report) {
  if (report) *report = ReadReport{};
  silence_openmesh();
  std::error_code ec;
  if (!fs::exists(path, ec)) fail(path, "no such file");
  if (!fs::is_regular_file(path, ec)) fail(path, "not a regular file");
  if (fs::file_size(path, ec) == 0) fail(path, "empty file");

  const std::string ext = lower_extension(path);
  WalkedMesh walk;
  if (ext == ".off") {
    walk = scan_off(path);
  } else if (ext == ".obj") {
    walk = scan_obj(path);
  } else if (ext == ".ply") {
    walk = scan_ply(path);
  } else if (ext == ".stl") {
    return read_stl(path);
  } else {
    fail(path, "unknown mesh extension '" + ext + "' (supported: .off .ply .obj .stl)");
  }

  // One walk of the file gives the mesh; OpenMesh's half-edge insertion checks its topology.
  TriangleMesh mesh;
  const Eigen::Index nv = static_cast<Eigen::Index>(walk.coords.size() / 3);
  const Eigen::Index nt = static_cast<Eigen::Index>(walk.source.size());
  mesh.vertices = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(
      walk.coords.data(), nv, 3);
  std::vector<double>().swap(walk.coords);
  mesh.faces = Eigen::Map<const Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>>(
      walk.triangles.data(), nt, 3);
  std::vector<int>().swap(walk.triangles);
  auto name_face = [&](Eigen::Index t) {
    std::string face =
        (walk.source_is_line ? "the face on line " : "face ") + std::to_string(walk.source[t]);
    // A polygon's triangles share its name: say which one.
    Eigen::Index first = t, last = t;
    while (first > 0 && walk.source[first - 1] == walk.source[t]) --first;
    while (last + 1 < nt && walk.source[last + 1] == walk.source[t]) ++last;
    if (last == first) return face;
    return "triangle " + std::to_string(t - first + 1) + " of " + std::to_string(last - first + 1) +
           " fanned from " + face;
  };
  auto name_vertex = [&](int v) { return std::to_string(v + walk.index_base); };
  const long long reoriented = orient_or_fail(path, mesh, name_face, name_vertex);
  if (report) report->reoriented_faces = reoriented;
  half_edge_mesh(path, "", mesh, name_face, name_vertex);
  return mesh;
}

namespace {

// half_edge_mesh for a mesh in memory: faces and vertices named by their 0-based indices.
IoMesh half_edge_mesh_in_memory(const std::string& name, const std::string& prefix,
                                const TriangleMesh& mesh) {
  return half_edge_mesh(
      name, prefix, mesh, [](Eigen::Index f) { return "face " + std::to_string(f); },
      [](int v) { return std::to_string(v); });
}

}  // namespace

void check_half_edge_faces(const TriangleMesh& mesh, const std::string& name) {
  half_edge_mesh_in_memory(name, "", mesh);
}

long long orient_and_check_faces(TriangleMesh& mesh, const std::string& name) {
  const auto name_face = [](Eigen::Index f) { return "face " + std::to_string(f); };
  const auto name_vertex = [](int v) { return std::to_string(v); };
  const long long reoriented = orient_or_fail(name, mesh, name_face, name_vertex);
  half_edge_mesh(name, "", mesh, name_face, name_vertex);
  return reoriented;
}

namespace {

// OFF, OBJ and PLY are written here rather than by OpenMesh, whose writers round coordinates to
// float: with 17 significant digits a text file reproduces every double, and binary PLY stores
// doubles. An ASCII PLY body is line for line an OFF body; only their headers differ.
/// Returns 0, or the errno of the first call that failed (EIO if it set none).
int write_exact(const fs::path& file, const TriangleMesh& mesh, const std::string& ext,
                bool binary) {
  errno = 0;
  std::FILE* out = std::fopen(file.c_str(), "wb");
  if (!out) return errno != 0 ? errno : EIO;
  std::vector<char> buffer(1 << 20);
  std::setvbuf(out, buffer.data(), _IOFBF, buffer.size());
  const bool obj = ext == ".obj";
  const long long nv = mesh.num_vertices(), nf = mesh.num_faces();
  if (ext == ".ply")
    std::fputs(ply_header(mesh, binary).c_str(), out);
  else if (obj)
    std::fprintf(out, "# %lld vertices, %lld faces\n", nv, nf);
  else
    std::fprintf(out, "OFF\n%lld %lld 0\n", nv, nf);
  if (ext == ".ply" && binary) {
    write_ply_binary_body(out, mesh);
  } else {
    for (Eigen::Index v = 0; v < nv; ++v)
      std::fprintf(out, obj ? "v %.17g %.17g %.17g\n" : "%.17g %.17g %.17g\n", mesh.vertices(v, 0),
                   mesh.vertices(v, 1), mesh.vertices(v, 2));
    for (Eigen::Index f = 0; f < nf; ++f) {
      if (obj)
        std::fprintf(out, "f %d %d %d\n", mesh.faces(f, 0) + 1, mesh.faces(f, 1) + 1,
                     mesh.faces(f, 2) + 1);
      else
        std::fprintf(out, "3 %d %d %d\n", mesh.faces(f, 0), mesh.faces(f, 1), mesh.faces(f, 2));
    }
  }
  // A failed write leaves its errno (and later writes to the full or read-only file system the
  // same one); fclose reports a failure of its final flush.
  const int write_errno = std::ferror(out) ? (errno != 0 ? errno : EIO) : 0;
  errno = 0;
  const int close_errno = std::fclose(out) == 0 ? 0 : (errno != 0 ? errno : EIO);
  return write_errno != 0 ? write_errno : close_errno;
}

}  // namespace

void write_mesh(const std::string& path, const TriangleMesh& mesh, bool binary, FaceCheck check) {
  silence_openmesh();
  const std::string ext = lower_extension(path);
  if (ext != ".off" && ext != ".ply" && ext != ".obj" && ext != ".stl")
    fail(path, "unknown mesh extension '" + ext + "' (supported: .off .ply .obj .stl)");

  // Writing a mesh that OpenMesh cannot represent would silently drop faces in an STL file, and
  // our own writers would write a file that no reader here accepts. The STL writer needs the
  // half-edge mesh whatever the caller vouches for.
  const IoMesh om = check == FaceCheck::half_edge || ext == ".stl"
                        ? half_edge_mesh_in_memory(path, "cannot write: ", mesh)
                        : IoMesh();

  // OpenMesh writes STL only (write_exact the rest). OFF has a binary variant, but few readers
  // besides OpenMesh accept it: OFF stays ASCII.
  OpenMesh::IO::Options opt;
  if (binary) opt += OpenMesh::IO::Options::Binary;

  // Temporary name in the same folder (rename is atomic only within a file system), keeping the
  // extension because OpenMesh chooses the writer from it.
  static std::atomic<unsigned> counter{0};
  fs::path target(path);
  fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  fs::path tmp = dir / ("." + target.stem().string() + ".tmp" + std::to_string(::getpid()) + "_" +
                        std::to_string(counter++) + target.extension().string());
  const int error = ext == ".stl" ? (OpenMesh::IO::write_mesh(om, tmp.string(), opt, 17) ? 0 : -1)
                                  : write_exact(tmp, mesh, ext, binary);
  if (error != 0) {
    std::error_code ec;
    fs::remove(tmp, ec);
    fail(path, error > 0 ? std::string("could not write the file: ") + std::strerror(error)
                         : "could not write the file (folder missing or not writable?)");
  }
  try {
    publish_durably(tmp, target);  // a frame or final.ply survives a crash of the machine too
  } catch (const std::runtime_error& e) {
    throw MeshError(e.what());
  }
}

}  // namespace mcf
