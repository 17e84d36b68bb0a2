#include "bases/vertex_ordering.h"

#include "core/undirected_graph.h"

#include <algorithm>

namespace mcf {
namespace {

struct Graph {
  std::vector<int> start, neighbour;  // CSR, sorted, no self loops
  int degree(int v) const { return start[std::size_t(v) + 1] - start[std::size_t(v)]; }
};

Graph vertex_graph(const Triangles& faces, int n) {
  std::vector<std::pair<int, int>> e;
  e.reserve(std::size_t(3 * faces.rows()));
  for (Eigen::Index f = 0; f < faces.rows(); ++f)
    for (int c = 0; c < 3; ++c) e.emplace_back(faces(f, c), faces(f, (c + 1) % 3));
  Graph g;
  undirected_graph(n, e, g.start, g.neighbour);
  return g;
}

/// Breadth-first from `root` in Cuthill–McKee's neighbour order: appends the vertices reached (its
/// component) to `out`; mark[v] == stamp means reached by this search.
void cuthill_mckee(const Graph& g, int root, std::vector<int>& mark, int stamp,
                   std::vector<int>& out) {
  const std::size_t first = out.size();
  out.push_back(root);
  mark[std::size_t(root)] = stamp;
  std::vector<int> next;
  for (std::size_t head = first; head < out.size(); ++head) {
    const int v = out[head];
    next.clear();
    for (int k = g.start[std::size_t(v)]; k < g.start[std::size_t(v) + 1]; ++k) {
      const int w = g.neighbour[std::size_t(k)];
      if (mark[std::size_t(w)] != stamp) {
        mark[std::size_t(w)] = stamp;
        next.push_back(w);
      }
    }
    std::sort(next.begin(), next.end(), [&](int a, int b) {
      return g.degree(a) != g.degree(b) ? g.degree(a) < g.degree(b) : a < b;
    });
    out.insert(out.end(), next.begin(), next.end());
  }
}

}  // namespace

std::vector<int> bandwidth_ordering(const Triangles& faces, int n) {
  const Graph g = vertex_graph(faces, n);
  std::vector<int> order, mark(std::size_t(n), 0), scratch;
  std::vector<char> numbered(std::size_t(n), 0);
  order.reserve(std::size_t(n));
  int stamp = 0;
  for (int seed = 0; seed < n; ++seed) {
    if (numbered[std::size_t(seed)] || g.degree(seed) == 0) continue;
    // A pseudo-peripheral root: two breadth-first sweeps, each from the last vertex the one
    // before reached (one of the farthest, the one of largest degree among the last level's).
    int root = seed;
    for (int sweep = 0; sweep < 2; ++sweep) {
      scratch.clear();
      cuthill_mckee(g, root, mark, ++stamp, scratch);
      root = scratch.back();
    }
    const std::size_t first = order.size();
    cuthill_mckee(g, root, mark, ++stamp, order);
    for (std::size_t k = first; k < order.size(); ++k) numbered[std::size_t(order[k])] = 1;
  }
  for (int v = 0; v < n; ++v)
    if (g.degree(v) == 0) order.push_back(v);
  return order;
}

}  // namespace mcf
