// Mesh file I/O through OpenMesh. OpenMesh only moves data between files and our Eigen arrays;
// the extra work here is making its silent failure modes loud (DESIGN.md, practical notes).

#include "datasets/mesh_io.h"

#include "datasets/ply_format.h"

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <string>
#include <unistd.h>
#include <vector>

namespace mcf {
namespace {

namespace fs = std::filesystem;

// Double-precision points: the default traits store floats, which would round every coordinate
// of an ASCII file we read and of every file we write.
struct IoTraits : OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3d;
  using Normal = OpenMesh::Vec3d;
};
using IoMesh = OpenMesh::TriMesh_ArrayKernelT<IoTraits>;

// OpenMesh prints warnings (e.g. "complex edge") on its own streams; we report problems through
// MeshError instead, so its chatter only confuses logs of batch runs.
void silence_openmesh() {
  static std::once_flag once;
  std::call_once(once, [] {
    ::omerr().disable();
    ::omlog().disable();
    ::omout().disable();
  });
}

std::string lower_extension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

[[noreturn]] void fail(const std::string& path, const std::string& problem) {
  throw MeshError(path + ": " + problem);
}

// What the file itself says it contains, counted independently of OpenMesh so that faces it
// dropped without an error (non-manifold "complex edges", repeated indices) are noticed.
struct FileCounts {
  long long vertices = -1;   // -1: unknown for this format
  long long triangles = -1;  // after fan triangulation; -1: unknown
  // Coordinates parsed in double precision (ASCII OFF/OBJ): OpenMesh's readers go through
  // floats, which would round every coordinate of an exactly written file.
  std::vector<double> coords;
};

// Strips '#' comments and surrounding blanks.
std::string clean_line(std::string line) {
  if (auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
  while (!line.empty() && std::isspace(static_cast<unsigned char>(line.back()))) line.pop_back();
  size_t start = 0;
  while (start < line.size() && std::isspace(static_cast<unsigned char>(line[start]))) ++start;
  return line.substr(start);
}

// ASCII OFF: header counts, finite coordinates, index range and the triangle count after fan
// triangulation. OpenMesh's reader is lenient about all of these.
FileCounts scan_off(const std::string& path) {
  std::ifstream in(path);
  if (!in) fail(path, "cannot open file");
  std::string line;
  std::string header;
  while (std::getline(in, line)) {
    header = clean_line(line);
    if (!header.empty()) break;
  }
  if (header.empty()) fail(path, "empty file (no OFF header)");
  std::istringstream hs(header);
  std::string magic;
  hs >> magic;
  if (magic.size() < 3 || magic.compare(magic.size() - 3, 3, "OFF") != 0)
    fail(path, "not an OFF file (header '" + magic + "')");
  std::string rest;
  std::getline(hs, rest);
  if (rest.find("BINARY") != std::string::npos) {
    // Binary OFF: we cannot cheaply re-parse; OpenMesh's own counts are all we have.
    return {};
  }
  rest = clean_line(rest);
  while (rest.empty() && std::getline(in, line)) rest = clean_line(line);
  long long nv = -1, nf = -1;
  {
    std::istringstream cs(rest);
    if (!(cs >> nv >> nf) || nv < 0 || nf < 0) fail(path, "bad OFF counts line '" + rest + "'");
  }
  FileCounts counts;
  counts.vertices = nv;
  long long v = 0;
  while (v < nv && std::getline(in, line)) {
    line = clean_line(line);
    if (line.empty()) continue;
    const char* p = line.c_str();
    for (int c = 0; c < 3; ++c) {
      char* end = nullptr;
      double x = std::strtod(p, &end);
      if (end == p) fail(path, "vertex " + std::to_string(v) + ": cannot parse coordinates '" + line + "'");
      if (!std::isfinite(x)) fail(path, "vertex " + std::to_string(v) + " has a non-finite coordinate ('" + line + "')");
      counts.coords.push_back(x);
      p = end;
    }
    ++v;
  }
  if (v < nv) fail(path, "file ends after " + std::to_string(v) + " of " + std::to_string(nv) + " vertices");
  long long f = 0, triangles = 0;
  while (f < nf && std::getline(in, line)) {
    line = clean_line(line);
    if (line.empty()) continue;
    std::istringstream fs_(line);
    long long k = 0;
    if (!(fs_ >> k) || k < 3) fail(path, "face " + std::to_string(f) + ": bad vertex count in '" + line + "'");
    for (long long i = 0; i < k; ++i) {
      long long idx;
      if (!(fs_ >> idx)) fail(path, "face " + std::to_string(f) + ": expected " + std::to_string(k) + " indices in '" + line + "'");
      if (idx < 0 || idx >= nv)
        fail(path, "face " + std::to_string(f) + " references vertex " + std::to_string(idx) +
                       " but the mesh has " + std::to_string(nv) + " vertices");
    }
    triangles += k - 2;
    ++f;
  }
  if (f < nf) fail(path, "file ends after " + std::to_string(f) + " of " + std::to_string(nf) + " faces");
  counts.triangles = triangles;
  return counts;
}

// OBJ: count 'v' and 'f' records; a face with k corners becomes k-2 triangles.
FileCounts scan_obj(const std::string& path) {
  std::ifstream in(path);
  if (!in) fail(path, "cannot open file");
  FileCounts counts;
  counts.vertices = 0;
  counts.triangles = 0;
  std::string line;
  long long line_number = 0, max_index = 0, max_index_line = 0;
  while (std::getline(in, line)) {
    ++line_number;
    line = clean_line(line);
    if (line.size() < 2) continue;
    if (line[0] == 'v' && std::isspace(static_cast<unsigned char>(line[1]))) {
      const char* p = line.c_str() + 1;
      for (int c = 0; c < 3; ++c) {
        char* end = nullptr;
        double x = std::strtod(p, &end);
        if (end == p) fail(path, "vertex " + std::to_string(counts.vertices) + ": cannot parse '" + line + "'");
        if (!std::isfinite(x)) fail(path, "vertex " + std::to_string(counts.vertices) + " has a non-finite coordinate ('" + line + "')");
        counts.coords.push_back(x);
        p = end;
      }
      ++counts.vertices;
    } else if (line[0] == 'f' && std::isspace(static_cast<unsigned char>(line[1]))) {
      std::istringstream fs_(line.substr(2));
      std::string tok;
      long long k = 0;
      while (fs_ >> tok) {
        ++k;
        // "v", "v/vt", "v/vt/vn" or "v//vn"; a negative v counts back from the last vertex read.
        // OpenMesh drops a face with a bad index as "non-manifold", which hides the real cause.
        char* end = nullptr;
        const long long v = std::strtoll(tok.c_str(), &end, 10);
        if (end == tok.c_str() || (*end != '\0' && *end != '/') || v == 0 || (v < 0 && -v > counts.vertices))
          fail(path, "line " + std::to_string(line_number) + ": face corner '" + tok + "' is not a vertex index (1.." +
                         std::to_string(counts.vertices) + " or -1..-" + std::to_string(counts.vertices) + " so far)");
        if (v > max_index) {
          max_index = v;
          max_index_line = line_number;
        }
      }
      if (k < 3) fail(path, "face with fewer than 3 corners: '" + line + "'");
      counts.triangles += k - 2;
    }
  }
  if (counts.vertices == 0 && counts.triangles == 0) fail(path, "no vertex or face records (not an OBJ file?)");
  if (max_index > counts.vertices)
    fail(path, "line " + std::to_string(max_index_line) + ": face refers to vertex " + std::to_string(max_index) +
                   " but the file has " + std::to_string(counts.vertices) + " vertices");
  return counts;
}

// PLY: a full walk of header and body (ply_format.cpp), which also gives exact doubles.
FileCounts scan_ply_counts(const std::string& path) {
  PlyContents ply = scan_ply(path);
  FileCounts counts;
  counts.vertices = ply.vertices;
  counts.triangles = ply.triangles;
  counts.coords = std::move(ply.coords);
  return counts;
}

// STL: ASCII counts 'facet' records, binary stores the triangle count at byte 80. Vertices are
// merged by OpenMesh (STL has no shared vertices), so their count is unknown in advance.
FileCounts scan_stl(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot open file");
  std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  FileCounts counts;
  auto start = data.find_first_not_of(" \t\r\n");
  bool ascii = start != std::string::npos && data.compare(start, 5, "solid") == 0 &&
               data.find("facet", start) != std::string::npos;
  if (ascii) {
    long long n = 0;
    for (size_t pos = data.find("facet"); pos != std::string::npos; pos = data.find("facet", pos + 5)) {
      // "endfacet" also contains "facet": count only the opening keyword.
      if (pos >= 3 && data.compare(pos - 3, 3, "end") == 0) continue;
      ++n;
    }
    counts.triangles = n;
  } else {
    if (data.size() < 84) fail(path, "binary STL shorter than its 84-byte header");
    std::uint32_t n = 0;
    std::memcpy(&n, data.data() + 80, 4);
    if (data.size() < 84 + 50ull * n) fail(path, "binary STL truncated (" + std::to_string(n) + " triangles announced)");
    counts.triangles = n;
  }
  return counts;
}

// STL has no vertex list to count against; OpenMesh merges equal corners, so two loaded vertices
// at exactly the same position mean it split a vertex to add a non-manifold face.
void check_no_split_vertices(const std::string& path, const IoMesh& om) {
  std::vector<std::array<double, 3>> points;
  points.reserve(om.n_vertices());
  for (auto vh : om.vertices()) {
    const auto& p = om.point(vh);
    points.push_back({p[0], p[1], p[2]});
  }
  std::sort(points.begin(), points.end());
  if (std::adjacent_find(points.begin(), points.end()) != points.end())
    fail(path, "non-manifold mesh: OpenMesh had to duplicate vertices to add faces around complex edges "
               "or vertices (an edge in more than two faces, or inconsistently oriented faces)");
}

}  // namespace

TriangleMesh read_mesh(const std::string& path) {
  silence_openmesh();
  std::error_code ec;
  if (!fs::exists(path, ec)) fail(path, "no such file");
  if (!fs::is_regular_file(path, ec)) fail(path, "not a regular file");
  if (fs::file_size(path, ec) == 0) fail(path, "empty file");

  const std::string ext = lower_extension(path);
  FileCounts expected;
  if (ext == ".off") expected = scan_off(path);
  else if (ext == ".obj") expected = scan_obj(path);
  else if (ext == ".ply") expected = scan_ply_counts(path);
  else if (ext == ".stl") expected = scan_stl(path);
  else fail(path, "unknown mesh extension '" + ext + "' (supported: .off .ply .obj .stl)");

  IoMesh om;
  OpenMesh::IO::Options opt;
  if (!OpenMesh::IO::read_mesh(om, path, opt)) fail(path, "OpenMesh could not parse the file");

  const long long nv = static_cast<long long>(om.n_vertices());
  const long long nf = static_cast<long long>(om.n_faces());
  // OpenMesh adds a face around a non-manifold ("complex") edge or vertex by duplicating its
  // vertices, so more vertices than the file has means exactly that.
  if (expected.vertices >= 0 && nv > expected.vertices)
    fail(path, "non-manifold mesh: OpenMesh had to duplicate " + std::to_string(nv - expected.vertices) +
                   " vertices to add faces around complex edges or vertices (an edge in more than two "
                   "faces, or inconsistently oriented faces)");
  if (expected.vertices >= 0 && nv != expected.vertices)
    fail(path, "the file declares " + std::to_string(expected.vertices) + " vertices but " +
                   std::to_string(nv) + " were read");
  if (ext == ".stl") check_no_split_vertices(path, om);
  if (expected.triangles >= 0 && nf < expected.triangles)
    fail(path, "only " + std::to_string(nf) + " of the file's " + std::to_string(expected.triangles) +
                   " triangles could be added: the mesh has non-manifold (complex) edges, repeated "
                   "vertex indices in a face, or inconsistently oriented faces");

  TriangleMesh mesh;
  mesh.vertices.resize(nv, 3);
  for (auto vh : om.vertices()) {
    const auto& p = om.point(vh);
    mesh.vertices.row(vh.idx()) << p[0], p[1], p[2];
  }
  // Prefer our double-precision parse, after checking it is the same vertex sequence.
  if (nv > 0 && static_cast<long long>(expected.coords.size()) == 3 * nv) {
    const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>> exact(expected.coords.data(), nv, 3);
    const double scale = std::max(1.0, exact.cwiseAbs().maxCoeff());
    if ((exact - mesh.vertices).cwiseAbs().maxCoeff() <= 1e-5 * scale) mesh.vertices = exact;
  }
  mesh.faces.resize(nf, 3);
  for (auto fh : om.faces()) {
    int c = 0;
    for (auto vh : om.fv_range(fh)) {
      if (c == 3) fail(path, "face " + std::to_string(fh.idx()) + " is not a triangle after loading");
      mesh.faces(fh.idx(), c++) = vh.idx();
    }
  }
  return mesh;
}

namespace {

// OFF, OBJ and PLY are written here rather than by OpenMesh, whose writers round coordinates to
// float: with 17 significant digits a text file reproduces every double, and binary PLY stores
// doubles. An ASCII PLY body is line for line an OFF body; only their headers differ.
bool write_exact(const fs::path& file, const TriangleMesh& mesh, const std::string& ext, bool binary) {
  std::FILE* out = std::fopen(file.c_str(), "wb");
  if (!out) return false;
  std::vector<char> buffer(1 << 20);
  std::setvbuf(out, buffer.data(), _IOFBF, buffer.size());
  const bool obj = ext == ".obj";
  const long long nv = mesh.num_vertices(), nf = mesh.num_faces();
  if (ext == ".ply") std::fputs(ply_header(mesh, binary).c_str(), out);
  else if (obj) std::fprintf(out, "# %lld vertices, %lld faces\n", nv, nf);
  else std::fprintf(out, "OFF\n%lld %lld 0\n", nv, nf);
  if (ext == ".ply" && binary) {
    write_ply_binary_body(out, mesh);
  } else {
    for (Eigen::Index v = 0; v < nv; ++v)
      std::fprintf(out, obj ? "v %.17g %.17g %.17g\n" : "%.17g %.17g %.17g\n", mesh.vertices(v, 0), mesh.vertices(v, 1),
                   mesh.vertices(v, 2));
    for (Eigen::Index f = 0; f < nf; ++f) {
      if (obj) std::fprintf(out, "f %d %d %d\n", mesh.faces(f, 0) + 1, mesh.faces(f, 1) + 1, mesh.faces(f, 2) + 1);
      else std::fprintf(out, "3 %d %d %d\n", mesh.faces(f, 0), mesh.faces(f, 1), mesh.faces(f, 2));
    }
  }
  const bool ok = std::ferror(out) == 0;
  return std::fclose(out) == 0 && ok;
}

}  // namespace

void write_mesh(const std::string& path, const TriangleMesh& mesh, bool binary) {
  silence_openmesh();
  const std::string ext = lower_extension(path);
  if (ext != ".off" && ext != ".ply" && ext != ".obj" && ext != ".stl")
    fail(path, "unknown mesh extension '" + ext + "' (supported: .off .ply .obj .stl)");

  IoMesh om;
  om.reserve(mesh.num_vertices(), 3 * mesh.num_faces(), mesh.num_faces());
  std::vector<IoMesh::VertexHandle> vh(mesh.num_vertices());
  for (Eigen::Index i = 0; i < mesh.num_vertices(); ++i)
    vh[i] = om.add_vertex(IoMesh::Point(mesh.vertices(i, 0), mesh.vertices(i, 1), mesh.vertices(i, 2)));
  for (Eigen::Index f = 0; f < mesh.num_faces(); ++f) {
    for (int c = 0; c < 3; ++c)
      if (mesh.faces(f, c) < 0 || mesh.faces(f, c) >= mesh.num_vertices())
        fail(path, "cannot write: face " + std::to_string(f) + " references vertex " +
                       std::to_string(mesh.faces(f, c)) + " but the mesh has " +
                       std::to_string(mesh.num_vertices()) + " vertices");
    auto fh = om.add_face(vh[mesh.faces(f, 0)], vh[mesh.faces(f, 1)], vh[mesh.faces(f, 2)]);
    // Writing a mesh that OpenMesh cannot represent would silently drop faces in the file.
    if (!fh.is_valid())
      fail(path, "cannot write: face " + std::to_string(f) + " makes the mesh non-manifold");
  }

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
  const bool written = ext == ".stl" ? OpenMesh::IO::write_mesh(om, tmp.string(), opt, 17)
                                     : write_exact(tmp, mesh, ext, binary);
  if (!written) {
    std::error_code ec;
    fs::remove(tmp, ec);
    fail(path, "could not write the file (folder missing or not writable?)");
  }
  std::error_code ec;
  fs::rename(tmp, target, ec);
  if (ec) {
    fs::remove(tmp, ec);
    fail(path, "cannot rename the temporary file into place: " + ec.message());
  }
}

}  // namespace mcf
