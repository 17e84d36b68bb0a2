#include "datasets/repair.h"

#include "datasets/validate.h"

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <vector>

namespace mcf {
namespace {

std::uint64_t edge_key(int a, int b) {
  if (a > b) std::swap(a, b);
  return (std::uint64_t(std::uint32_t(a)) << 32) | std::uint32_t(b);
}

double area_of(const TriangleMesh& mesh, int a, int b, int c) {
  const Eigen::Vector3d pa = mesh.vertices.row(a), pb = mesh.vertices.row(b),
                        pc = mesh.vertices.row(c);
  return 0.5 * (pb - pa).cross(pc - pa).norm();
}

/// The faces around each undirected edge, as sorted (key, face) pairs.
std::vector<std::pair<std::uint64_t, Eigen::Index>> edge_faces(const Triangles& faces) {
  std::vector<std::pair<std::uint64_t, Eigen::Index>> uses;
  uses.reserve(std::size_t(3 * faces.rows()));
  for (Eigen::Index f = 0; f < faces.rows(); ++f)
    for (int k = 0; k < 3; ++k) uses.emplace_back(edge_key(faces(f, k), faces(f, (k + 1) % 3)), f);
  std::sort(uses.begin(), uses.end());
  return uses;
}

}  // namespace

DegenerateRepair repair_degenerate_faces(TriangleMesh& mesh) {
  DegenerateRepair report;
  const Eigen::Index n = mesh.num_vertices();
  std::vector<int> to(static_cast<std::size_t>(n));  // merged vertex -> its survivor
  std::iota(to.begin(), to.end(), 0);
  auto find = [&](int v) {
    while (to[static_cast<std::size_t>(v)] != v) v = to[static_cast<std::size_t>(v)];
    return v;
  };
  const Eigen::Index faces_before = mesh.num_faces();
  // Each pass handles the degenerate faces that touch no vertex an earlier flip or collapse of
  // the same pass changed (either changes its neighbours), then drops the faces left with a
  // repeated corner. Every pass removes its first degenerate face (a flip creates none, a
  // collapse drops at least that face), so this ends.
  for (;;) {
    const std::vector<Eigen::Index> degenerate = degenerate_faces(mesh);
    if (degenerate.empty()) break;
    const double min_area = degenerate_area(mesh);
    const auto uses = edge_faces(mesh.faces);
    auto faces_on = [&](int a, int b) {
      const std::uint64_t key = edge_key(a, b);
      const auto lo =
          std::lower_bound(uses.begin(), uses.end(), std::make_pair(key, Eigen::Index(0)));
      std::vector<Eigen::Index> out;
      for (auto it = lo; it != uses.end() && it->first == key; ++it) out.push_back(it->second);
      return out;
    };
    std::vector<char> touched(static_cast<std::size_t>(n), 0);
    std::vector<char> zero_area(static_cast<std::size_t>(mesh.num_faces()), 0);
    for (Eigen::Index f : degenerate) {
      const int v[3] = {mesh.faces(f, 0), mesh.faces(f, 1), mesh.faces(f, 2)};
      if (touched[v[0]] || touched[v[1]] || touched[v[2]]) continue;
      double length[3];  // length[k]: edge (v[k], v[k+1])
      for (int k = 0; k < 3; ++k)
        length[k] = (mesh.vertices.row(v[(k + 1) % 3]) - mesh.vertices.row(v[k])).norm();
      int shortest = 0, longest = 0;
      for (int k = 1; k < 3; ++k) {
        if (length[k] < length[shortest]) shortest = k;
        if (length[k] > length[longest]) longest = k;
      }
      // The cap as (a, b, c) with b opposite the longest edge (c, a).
      const int b = v[(longest + 2) % 3], c = v[longest], a = v[(longest + 1) % 3];
      if (length[shortest] > 0.0) {
        const std::vector<Eigen::Index> across = faces_on(c, a);
        if (across.size() == 2) {
          const Eigen::Index g = across[0] == f ? across[1] : across[0];
          int d = -1;
          for (int k = 0; k < 3; ++k)
            if (mesh.faces(g, k) != a && mesh.faces(g, k) != c) d = mesh.faces(g, k);
          if (d >= 0 && !touched[d] && faces_on(b, d).empty() &&
              area_of(mesh, a, b, d) > min_area && area_of(mesh, b, c, d) > min_area) {
            mesh.faces.row(f) << a, b, d;
            mesh.faces.row(g) << b, c, d;
            for (int x : {a, b, c, d}) touched[x] = 1;
            ++report.flipped_faces;
            ++report.degenerate_faces;
            continue;
          }
        }
      }
      const int p = v[shortest], q = v[(shortest + 1) % 3];
      // Coincident corners: either may go. Else the corner between the other two goes (it lies
      // on the edge that stays), if the shortest edge has it.
      const int gone = length[shortest] > 0.0 && (b == p || b == q) ? b : std::max(p, q);
      to[static_cast<std::size_t>(gone)] = gone == p ? q : p;
      for (int x : v) touched[x] = 1;
      ++report.merged_vertices;
    }
    for (Eigen::Index f : degenerate) zero_area[static_cast<std::size_t>(f)] = 1;
    Triangles kept(mesh.num_faces(), 3);
    Eigen::Index m = 0;
    for (Eigen::Index f = 0; f < mesh.num_faces(); ++f) {
      const int x = find(mesh.faces(f, 0)), y = find(mesh.faces(f, 1)), z = find(mesh.faces(f, 2));
      if (x == y || y == z || z == x) {
        report.degenerate_faces += zero_area[static_cast<std::size_t>(f)];
        continue;
      }
      kept.row(m++) << x, y, z;
    }
    kept.conservativeResize(m, 3);
    mesh.faces = std::move(kept);
  }
  report.removed_faces = faces_before - mesh.num_faces();
  return report;
}

}  // namespace mcf
