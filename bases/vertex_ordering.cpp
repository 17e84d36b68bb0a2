#include "bases/vertex_ordering.h"

#include "core/undirected_graph.h"

#include <algorithm>
#include <cstdint>

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
/// component) to `out`; mark[v] == stamp means reached by this search. The order (degree, index)
/// is that of the keys degree * 2^32 + index; a vertex's few new neighbours are sorted by
/// insertion. The queue visits the graph in no local order: the rows of the vertices a few places
/// ahead in it are fetched early, and their neighbours' marks and degrees a few places after.
void cuthill_mckee(const Graph& g, int root, std::vector<int>& mark, int stamp,
                   std::vector<int>& out) {
  const std::size_t first = out.size();
  out.push_back(root);
  mark[std::size_t(root)] = stamp;
  std::vector<std::uint64_t> next;
  constexpr std::size_t ahead = 8;
  for (std::size_t head = first; head < out.size(); ++head) {
    if (head + 2 * ahead < out.size())
      __builtin_prefetch(&g.start[std::size_t(out[head + 2 * ahead])]);
    if (head + ahead < out.size()) {
      const int u = out[head + ahead];
      for (int k = g.start[std::size_t(u)]; k < g.start[std::size_t(u) + 1]; ++k) {
        const int w = g.neighbour[std::size_t(k)];
        __builtin_prefetch(&mark[std::size_t(w)]);
        __builtin_prefetch(&g.start[std::size_t(w)]);
      }
    }
    const int v = out[head];
    next.clear();
    for (int k = g.start[std::size_t(v)]; k < g.start[std::size_t(v) + 1]; ++k) {
      const int w = g.neighbour[std::size_t(k)];
      if (mark[std::size_t(w)] != stamp) {
        mark[std::size_t(w)] = stamp;
        next.push_back(std::uint64_t(g.degree(w)) << 32 | std::uint32_t(w));
      }
    }
    if (next.size() > 16) {
      std::sort(next.begin(), next.end());
    } else {
      for (std::size_t i = 1; i < next.size(); ++i)
        for (std::size_t j = i; j > 0 && next[j] < next[j - 1]; --j)
          std::swap(next[j], next[j - 1]);
    }
    for (const std::uint64_t key : next) out.push_back(int(std::uint32_t(key)));
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
