// Mesh validation. Everything is O(m log m): edges are found by sorting 64-bit keys, components
// by union-find, so a ~1M-face mesh validates in well under a second.

#include "datasets/validate.h"

#include "datasets/edge_uses.h"
#include "datasets/referenced_vertices.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <string>
#include <vector>

namespace mcf {
namespace {

[[noreturn]] void fail(const std::string& name, const std::string& problem) {
  throw MeshError(name + ": " + problem);
}

struct UnionFind {
  std::vector<int> parent;
  explicit UnionFind(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];  // path halving
    return x;
  }
  void unite(int a, int b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

int edge_a(std::uint64_t key) {
  return static_cast<int>(key >> 32);
}
int edge_b(std::uint64_t key) {
  return static_cast<int>(key & 0xffffffffu);
}

double face_area(const TriangleMesh& mesh, Eigen::Index f) {
  const Eigen::Vector3d a = mesh.vertices.row(mesh.faces(f, 0));
  const Eigen::Vector3d b = mesh.vertices.row(mesh.faces(f, 1));
  const Eigen::Vector3d c = mesh.vertices.row(mesh.faces(f, 2));
  return 0.5 * (b - a).cross(c - a).norm();
}

/// Non-empty, finite coordinates, vertex indices in range, no vertex twice in a face.
void check_faces(const TriangleMesh& mesh, const std::string& name) {
  const Eigen::Index n = mesh.num_vertices();
  const Eigen::Index m = mesh.num_faces();
  if (n == 0 || m == 0)
    fail(name, "empty mesh (" + std::to_string(n) + " vertices, " + std::to_string(m) + " faces)");

  for (Eigen::Index v = 0; v < n; ++v)
    if (!mesh.vertices.row(v).allFinite())
      fail(name, "vertex " + std::to_string(v) + " has a non-finite (NaN or inf) coordinate");

  for (Eigen::Index f = 0; f < m; ++f) {
    for (int c = 0; c < 3; ++c) {
      const int v = mesh.faces(f, c);
      if (v < 0 || v >= n)
        fail(name, "face " + std::to_string(f) + " references vertex " + std::to_string(v) +
                       " but the mesh has " + std::to_string(n) + " vertices");
    }
    const int a = mesh.faces(f, 0), b = mesh.faces(f, 1), c = mesh.faces(f, 2);
    if (a == b || b == c || c == a)
      fail(name, "face " + std::to_string(f) + " repeats a vertex (" + std::to_string(a) + ", " +
                     std::to_string(b) + ", " + std::to_string(c) + ")");
  }
}

/// The smallest area a face of this mesh may have (degenerate_faces).
double min_face_area(const TriangleMesh& mesh, const std::vector<char>& referenced) {
  const double diag2 = bounds_of(mesh.vertices, referenced)
                           .extent()
                           .squaredNorm();  // a stray vertex is not the model's size
  return 1e-14 * diag2;
}

bool is_degenerate(double area, double min_area) {
  return area == 0.0 || area <= min_area;
}

/// The total area; a degenerate face throws unless options.keep_degenerate, which counts it.
double checked_area(const TriangleMesh& mesh, const std::string& name,
                    const std::vector<char>& referenced, const ValidateOptions& options,
                    MeshReport& report) {
  const double min_area = min_face_area(mesh, referenced);
  double total = 0;
  for (Eigen::Index f = 0; f < mesh.num_faces(); ++f) {
    const double area = face_area(mesh, f);
    if (is_degenerate(area, min_area)) {
      if (!options.keep_degenerate)
        fail(name, "face " + std::to_string(f) + " is degenerate (area " + std::to_string(area) +
                       ", vertices " + std::to_string(mesh.faces(f, 0)) + ", " +
                       std::to_string(mesh.faces(f, 1)) + ", " + std::to_string(mesh.faces(f, 2)) +
                       ")" + options.degenerate_hint);
      ++report.degenerate_faces;
    }
    total += area;
  }
  return total;
}

/// What the edges tell: boundary edges joined into loops, and the edges of each component
/// (its root in the components' union-find).
struct EdgeCounts {
  UnionFind boundary;
  std::vector<char> on_boundary;
  std::vector<long long> edges_of_root;
};

/// Walks the undirected edges (a run of equal keys in the sorted list is one edge and its
/// faces): a non-manifold edge throws, misoriented ones are counted in `report`.
EdgeCounts count_edges(const TriangleMesh& mesh, const std::string& name, UnionFind& uf,
                       MeshReport& report) {
  const Eigen::Index n = mesh.num_vertices();
  const auto uses = sorted_edge_uses(mesh.faces);
  EdgeCounts e{UnionFind(static_cast<size_t>(n)), std::vector<char>(n, 0),
               std::vector<long long>(n, 0)};
  for (size_t i = 0; i < uses.size();) {
    size_t j = i;
    while (j < uses.size() && uses[j].key == uses[i].key) ++j;
    const int a = edge_a(uses[i].key), b = edge_b(uses[i].key);
    if (j - i > 2)
      fail(name, "non-manifold edge (" + std::to_string(a) + ", " + std::to_string(b) +
                     ") is shared by " + std::to_string(j - i) + " faces (" +
                     std::to_string(uses[i].face) + ", " + std::to_string(uses[i + 1].face) + ", " +
                     std::to_string(uses[i + 2].face) + ", ...)");
    if (j - i == 1) {
      e.boundary.unite(a, b);
      e.on_boundary[a] = e.on_boundary[b] = 1;
    } else if (uses[i].forward == uses[i + 1].forward) {
      ++report.misoriented_edges;
    }
    ++e.edges_of_root[uf.find(a)];
    i = j;
  }
  return e;
}

/// Per component: referenced vertices, edges, faces, boundary loops -> χ_c and genus.
void count_components(const TriangleMesh& mesh, const std::vector<char>& referenced, UnionFind& uf,
                      EdgeCounts& e, MeshReport& report) {
  const Eigen::Index n = mesh.num_vertices();
  std::vector<long long> verts_of_root(n, 0), faces_of_root(n, 0), loops_of_root(n, 0);
  for (Eigen::Index v = 0; v < n; ++v) {
    if (!referenced[v]) {
      ++report.unreferenced_vertices;
      continue;
    }
    const int root = uf.find(static_cast<int>(v));
    ++verts_of_root[root];
    if (e.on_boundary[v] && e.boundary.find(static_cast<int>(v)) == v) ++loops_of_root[root];
  }
  for (Eigen::Index f = 0; f < mesh.num_faces(); ++f) ++faces_of_root[uf.find(mesh.faces(f, 0))];

  for (Eigen::Index v = 0; v < n; ++v) {
    if (!referenced[v] || uf.find(static_cast<int>(v)) != v) continue;
    ++report.connected_components;
    const long long chi = verts_of_root[v] - e.edges_of_root[v] + faces_of_root[v];
    report.euler_characteristic += chi;
    report.boundary_loops += loops_of_root[v];
    report.genus += (2 - chi - loops_of_root[v]) / 2;
  }
}

}  // namespace

MeshReport validate_mesh(const TriangleMesh& mesh, const std::string& name,
                         const ValidateOptions& options) {
  check_faces(mesh, name);
  const std::vector<char> referenced = referenced_vertices(mesh.num_vertices(), mesh.faces);
  MeshReport report;
  report.vertices = mesh.num_vertices();
  report.faces = mesh.num_faces();
  report.area = checked_area(mesh, name, referenced, options, report);
  UnionFind uf(static_cast<size_t>(mesh.num_vertices()));
  for (Eigen::Index f = 0; f < mesh.num_faces(); ++f) {
    uf.unite(mesh.faces(f, 0), mesh.faces(f, 1));
    uf.unite(mesh.faces(f, 0), mesh.faces(f, 2));
  }
  EdgeCounts edges = count_edges(mesh, name, uf, report);
  count_components(mesh, referenced, uf, edges, report);
  return report;
}

double degenerate_area(const TriangleMesh& mesh) {
  return min_face_area(mesh, referenced_vertices(mesh.num_vertices(), mesh.faces));
}

std::vector<Eigen::Index> degenerate_faces(const TriangleMesh& mesh) {
  const double min_area = degenerate_area(mesh);
  std::vector<Eigen::Index> out;
  for (Eigen::Index f = 0; f < mesh.num_faces(); ++f)
    if (is_degenerate(face_area(mesh, f), min_area)) out.push_back(f);
  return out;
}

std::vector<std::array<int, 2>> boundary_edges(const Triangles& faces) {
  const auto uses = sorted_edge_uses(faces);
  std::vector<std::array<int, 2>> out;
  for (size_t i = 0; i < uses.size();) {
    size_t j = i;
    while (j < uses.size() && uses[j].key == uses[i].key) ++j;
    if (j - i == 1) out.push_back({edge_a(uses[i].key), edge_b(uses[i].key)});
    i = j;
  }
  return out;
}

std::vector<int> boundary_vertices(const TriangleMesh& mesh) {
  std::vector<int> out;
  for (const auto& e : boundary_edges(mesh.faces)) {
    out.push_back(e[0]);
    out.push_back(e[1]);
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

double surface_area(const TriangleMesh& mesh) {
  double area = 0.0;
  for (Eigen::Index f = 0; f < mesh.num_faces(); ++f) area += face_area(mesh, f);
  return area;
}

}  // namespace mcf
