#include "datasets/repair.h"

#include "datasets/validate.h"

#include <algorithm>
#include <numeric>
#include <vector>

namespace mcf {

CollapseReport collapse_degenerate_faces(TriangleMesh& mesh) {
  CollapseReport report;
  const Eigen::Index n = mesh.num_vertices();
  std::vector<int> to(static_cast<std::size_t>(n));  // merged vertex -> its survivor
  std::iota(to.begin(), to.end(), 0);
  auto find = [&](int v) {
    while (to[static_cast<std::size_t>(v)] != v) v = to[static_cast<std::size_t>(v)];
    return v;
  };
  const Eigen::Index faces_before = mesh.num_faces();
  // Each pass collapses the degenerate faces that touch no vertex an earlier collapse of the
  // same pass moved (a collapse changes its neighbours' shapes), then drops the faces left with a
  // repeated corner; every pass removes at least one face, so this ends.
  for (;;) {
    const std::vector<Eigen::Index> degenerate = degenerate_faces(mesh);
    if (degenerate.empty()) break;
    std::vector<char> touched(static_cast<std::size_t>(n), 0);
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
      const int p = v[shortest], q = v[(shortest + 1) % 3];
      int gone;
      if (length[shortest] == 0.0) {
        gone = std::max(p, q);
      } else {
        // The vertex opposite the longest edge lies between the other two on their line.
        const int middle = v[(longest + 2) % 3];
        gone = middle == p || middle == q ? middle : std::max(p, q);
      }
      const int kept = gone == p ? q : p;
      to[static_cast<std::size_t>(gone)] = kept;
      for (int k = 0; k < 3; ++k) touched[v[k]] = 1;
      ++report.merged_vertices;
    }
    std::vector<char> zero_area(static_cast<std::size_t>(mesh.num_faces()), 0);
    for (Eigen::Index f : degenerate) zero_area[static_cast<std::size_t>(f)] = 1;
    Triangles kept(mesh.num_faces(), 3);
    Eigen::Index m = 0;
    for (Eigen::Index f = 0; f < mesh.num_faces(); ++f) {
      const int a = find(mesh.faces(f, 0)), b = find(mesh.faces(f, 1)), c = find(mesh.faces(f, 2));
      if (a == b || b == c || c == a) {
        report.degenerate_faces += zero_area[static_cast<std::size_t>(f)];
        continue;
      }
      kept.row(m++) << a, b, c;
    }
    kept.conservativeResize(m, 3);
    mesh.faces = std::move(kept);
  }
  report.removed_faces = faces_before - mesh.num_faces();
  return report;
}

}  // namespace mcf
