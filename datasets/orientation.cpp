// Breadth-first orientation over edge-adjacent faces. Edges are found by sorting 64-bit keys of
// the faces' corner pairs (datasets/edge_uses.h), so a ~1M-face mesh is oriented in well under a
// second.

#include "datasets/orientation.h"

#include "datasets/edge_uses.h"

#include <algorithm>
#include <cstdint>
#include <deque>
#include <utility>

namespace mcf {
namespace {

/// A neighbour across an edge, and whether the two faces run that edge the same way (then one of
/// them has to be reversed).
struct Link {
  Eigen::Index face;
  bool same_direction;
  std::uint64_t key;
};

}  // namespace

OrientationResult orient_faces(Triangles& faces) {
  OrientationResult result;
  const Eigen::Index m = faces.rows();
  std::vector<EdgeUse> uses = sorted_edge_uses(faces);

  // Adjacency in CSR form: each manifold interior edge links its two faces both ways. An edge in
  // three or more faces has no orientation to agree on: the one whose third face comes first is
  // reported, as the first face a half-edge mesh built in face order could not add.
  std::vector<std::pair<Eigen::Index, Link>> links;
  links.reserve(uses.size());
  Eigen::Index first_third_face = m;
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i;
    while (j < uses.size() && uses[j].key == uses[i].key) ++j;
    if (j - i > 2 && uses[i + 2].face < first_third_face) {
      first_third_face = uses[i + 2].face;
      result.problem = OrientationResult::Problem::non_manifold_edge;
      result.edge = edge_vertices(uses[i].key);
      result.faces = {uses[i].face, uses[i + 1].face, uses[i + 2].face};
    } else if (j - i == 2) {
      const bool same = uses[i].forward == uses[i + 1].forward;
      links.push_back({uses[i].face, {uses[i + 1].face, same, uses[i].key}});
      links.push_back({uses[i + 1].face, {uses[i].face, same, uses[i].key}});
    }
    i = j;
  }
  if (result.problem != OrientationResult::Problem::none) return result;
  std::vector<EdgeUse>().swap(uses);  // a 1M-face mesh's uses and links are ~100 MB each
  std::vector<Eigen::Index> start(static_cast<std::size_t>(m + 1), 0);
  for (const auto& l : links) ++start[static_cast<std::size_t>(l.first + 1)];
  for (Eigen::Index f = 0; f < m; ++f)
    start[static_cast<std::size_t>(f + 1)] += start[static_cast<std::size_t>(f)];
  std::vector<Link> adjacent(links.size());
  {
    std::vector<Eigen::Index> next(start.begin(), start.end() - 1);
    for (const auto& l : links) adjacent[static_cast<std::size_t>(next[l.first]++)] = l.second;
  }
  std::vector<std::pair<Eigen::Index, Link>>().swap(links);

  // flip[f]: 0 unvisited, 1 keep, 2 reverse.
  std::vector<char> flip(static_cast<std::size_t>(m), 0);
  std::vector<Eigen::Index> component;
  std::deque<Eigen::Index> queue;
  std::vector<Eigen::Index> to_reverse;
  for (Eigen::Index seed = 0; seed < m; ++seed) {
    if (flip[static_cast<std::size_t>(seed)]) continue;
    component.clear();
    flip[static_cast<std::size_t>(seed)] = 1;
    queue.push_back(seed);
    while (!queue.empty()) {
      const Eigen::Index f = queue.front();
      queue.pop_front();
      component.push_back(f);
      const bool f_reversed = flip[static_cast<std::size_t>(f)] == 2;
      for (Eigen::Index k = start[static_cast<std::size_t>(f)];
           k < start[static_cast<std::size_t>(f + 1)]; ++k) {
        const Link& l = adjacent[static_cast<std::size_t>(k)];
        // Faces running the shared edge the same way need opposite decisions.
        const char wanted = (f_reversed != l.same_direction) ? 2 : 1;
        char& g = flip[static_cast<std::size_t>(l.face)];
        if (g == 0) {
          g = wanted;
          queue.push_back(l.face);
        } else if (g != wanted) {
          result.problem = OrientationResult::Problem::non_orientable;
          result.edge = edge_vertices(l.key);
          result.faces = {f, l.face};
          return result;
        }
      }
    }
    long long reversed = 0;
    for (Eigen::Index f : component) reversed += flip[static_cast<std::size_t>(f)] == 2;
    // Keep the orientation most of the component's faces have.
    const bool invert = 2 * reversed > static_cast<long long>(component.size());
    for (Eigen::Index f : component)
      if ((flip[static_cast<std::size_t>(f)] == 2) != invert) to_reverse.push_back(f);
  }
  for (Eigen::Index f : to_reverse) std::swap(faces(f, 1), faces(f, 2));
  result.reoriented = static_cast<long long>(to_reverse.size());
  return result;
}

}  // namespace mcf
