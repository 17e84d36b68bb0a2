#include "bases/surface_hierarchy.h"

#include "core/compressed_sets.h"
#include "core/galerkin_pattern.h"
#include "core/parallel.h"
#include "core/undirected_graph.h"

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <queue>
#include <tuple>

namespace mcf {
namespace {

/// One level as the coarsening sees it: points, the vertex graph (CSR, sorted, no self loops) and
/// triangles.
struct LevelMesh {
  Positions points;
  std::vector<int> start, neighbour;  // neighbours of v: neighbour[start[v] .. start[v+1])
  std::vector<std::array<int, 3>> triangles;
  int size() const { return int(points.rows()); }
};

/// CSR of the undirected graph of `pairs` (each given once or twice) on n vertices.
void build_graph(int n, std::vector<std::pair<int, int>>& pairs, LevelMesh& level) {
  undirected_graph(n, pairs, level.start, level.neighbour);
}

LevelMesh finest_level(const Positions& vertices, const Triangles& faces) {
  LevelMesh level;
  level.points = vertices;
  std::vector<std::pair<int, int>> edges;
  edges.reserve(std::size_t(3 * faces.rows()));
  level.triangles.resize(std::size_t(faces.rows()));
  for (Eigen::Index f = 0; f < faces.rows(); ++f) {
    const std::array<int, 3> t = {faces(f, 0), faces(f, 1), faces(f, 2)};
    level.triangles[std::size_t(f)] = t;
    for (int c = 0; c < 3; ++c) edges.emplace_back(t[std::size_t(c)], t[std::size_t((c + 1) % 3)]);
  }
  build_graph(int(vertices.rows()), edges, level);
  return level;
}

/// Barycentric coordinates of x projected onto the plane of (a, b, c); false for a degenerate
/// triangle.
bool barycentric(const Eigen::RowVector3d& x, const Eigen::RowVector3d& a,
                 const Eigen::RowVector3d& b, const Eigen::RowVector3d& c,
                 std::array<double, 3>& w) {
  const Eigen::RowVector3d e0 = b - a, e1 = c - a, p = x - a;
  const double d00 = e0.dot(e0), d01 = e0.dot(e1), d11 = e1.dot(e1);
  const double d20 = p.dot(e0), d21 = p.dot(e1);
  const double denom = d00 * d11 - d01 * d01;
  if (!(denom > 1e-14 * d00 * d11)) return false;
  w[1] = (d11 * d20 - d01 * d21) / denom;
  w[2] = (d00 * d21 - d01 * d20) / denom;
  w[0] = 1.0 - w[1] - w[2];
  return true;
}

/// A cell's key at a vertex: the distance to its sample and the sample's index, ordered
/// lexicographically (ties in distance go to the smaller sample index).
struct CellKey {
  double distance;
  int sample;
  bool operator<(const CellKey& o) const {
    return distance < o.distance || (distance == o.distance && sample < o.sample);
  }
  bool operator==(const CellKey& o) const = default;
};

/// graph_voronoi_cells by multi-source Dijkstra: the definition, and the fallback of the parallel
/// search.
std::vector<int> graph_voronoi_dijkstra(const std::vector<int>& start,
                                        const std::vector<int>& neighbour, const Positions& points,
                                        const std::vector<int>& sample) {
  const int n = int(points.rows());
  std::vector<double> dist(std::size_t(n), std::numeric_limits<double>::infinity());
  std::vector<int> label(std::size_t(n), std::numeric_limits<int>::max());
  using Entry = std::tuple<double, int, int>;  // distance, label, vertex
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> queue;
  for (int v = 0; v < n; ++v)
    if (sample[std::size_t(v)] >= 0) {
      dist[std::size_t(v)] = 0;
      label[std::size_t(v)] = sample[std::size_t(v)];
      queue.emplace(0.0, label[std::size_t(v)], v);
    }
  while (!queue.empty()) {
    const auto [d, lab, v] = queue.top();
    queue.pop();
    if (d != dist[std::size_t(v)] || lab != label[std::size_t(v)]) continue;
    for (int k = start[std::size_t(v)]; k < start[std::size_t(v) + 1]; ++k) {
      const int w = neighbour[std::size_t(k)];
      const double nd = d + (points.row(v) - points.row(w)).norm();
      if (nd < dist[std::size_t(w)] ||
          (nd == dist[std::size_t(w)] && lab < label[std::size_t(w)])) {
        dist[std::size_t(w)] = nd;
        label[std::size_t(w)] = lab;
        queue.emplace(nd, lab, w);
      }
    }
  }
  return label;
}

}  // namespace

std::vector<int> graph_voronoi_cells(const std::vector<int>& start,
                                     const std::vector<int>& neighbour, const Positions& points,
                                     const std::vector<int>& sample) {
  const int n = int(points.rows());
  constexpr double inf = std::numeric_limits<double>::infinity();
  auto initial = [&](int v) {
    const int s = sample[std::size_t(v)];
    return s >= 0 ? CellKey{0.0, s} : CellKey{inf, std::numeric_limits<int>::max()};
  };
  // Edge lengths per stored entry (|p_v - p_w| is the same number either way round).
  std::vector<double> length(neighbour.size());
  parallel_for_indices(n, 2048, [&](int v) {
    for (int k = start[std::size_t(v)]; k < start[std::size_t(v) + 1]; ++k)
      length[std::size_t(k)] = (points.row(v) - points.row(neighbour[std::size_t(k)])).norm();
  });
  // Jacobi sweeps of the equations that Dijkstra's keys satisfy,
  //   key(w) = min(initial(w), min over neighbours v of (key(v).distance + |p_v - p_w|,
  //   key(v).sample)),
  // each vertex recomputed from its neighbours' keys of the sweep before (so each sweep is
  // deterministic), and only when one of them changed. A sweep that changes nothing leaves a
  // solution of the equations.
  std::vector<CellKey> key(static_cast<std::size_t>(n)), next(static_cast<std::size_t>(n));
  std::vector<char> changed(static_cast<std::size_t>(n), 1),
      changed_next(static_cast<std::size_t>(n));
  for (int v = 0; v < n; ++v) key[std::size_t(v)] = initial(v);
  constexpr int max_sweeps = 64;  // beyond a few hops of paths, the priority queue is the cheaper
  bool converged = false;
  for (int sweep = 0; sweep < max_sweeps && !converged; ++sweep) {
    std::atomic<bool> any{false};
    parallel_for_indices(n, 2048, [&](int w) {
      const int b = start[std::size_t(w)], e = start[std::size_t(w) + 1];
      bool stale = false;
      for (int k = b; k < e && !stale; ++k) stale = changed[std::size_t(neighbour[std::size_t(k)])];
      CellKey best = key[std::size_t(w)];
      if (stale) {
        best = initial(w);
        for (int k = b; k < e; ++k) {
          const CellKey& kv = key[std::size_t(neighbour[std::size_t(k)])];
          const CellKey r{kv.distance + length[std::size_t(k)], kv.sample};
          if (r < best) best = r;
        }
      }
      next[std::size_t(w)] = best;
      const bool c = !(best == key[std::size_t(w)]);
      changed_next[std::size_t(w)] = c;
      if (c) any.store(true, std::memory_order_relaxed);
    });
    key.swap(next);
    changed.swap(changed_next);
    converged = !any.load();
  }
  // The equations have one solution when every vertex off its initial key takes it from a
  // neighbour strictly nearer its sample (an edge too short to add to a distance, e.g. between
  // coincident points, can break that): then it is Dijkstra's. Otherwise Dijkstra decides.
  std::atomic<bool> unique{converged};
  if (converged)
    parallel_for_indices(n, 2048, [&](int w) {
      const CellKey kw = key[std::size_t(w)];
      if (kw == initial(w)) return;
      for (int k = start[std::size_t(w)]; k < start[std::size_t(w) + 1]; ++k) {
        const CellKey& kv = key[std::size_t(neighbour[std::size_t(k)])];
        if (kv.distance < kw.distance &&
            CellKey{kv.distance + length[std::size_t(k)], kv.sample} == kw)
          return;
      }
      unique.store(false, std::memory_order_relaxed);
    });
  if (!unique.load()) return graph_voronoi_dijkstra(start, neighbour, points, sample);
  std::vector<int> label(static_cast<std::size_t>(n));
  parallel_for_indices(n, 4096, [&](int v) { label[std::size_t(v)] = key[std::size_t(v)].sample; });
  return label;
}

namespace {

/// Step 1: a maximal independent set, greedily in index order: per fine vertex its coarse index
/// (-1 off the set); returns the set's size.
int independent_set(const LevelMesh& fine, std::vector<int>& coarse_index) {
  const int n = fine.size();
  coarse_index.assign(std::size_t(n), -1);
  std::vector<char> blocked(std::size_t(n), 0);
  int nc = 0;
  for (int v = 0; v < n; ++v) {
    if (blocked[std::size_t(v)]) continue;
    coarse_index[std::size_t(v)] = nc++;
    blocked[std::size_t(v)] = 1;
    for (int k = fine.start[std::size_t(v)]; k < fine.start[std::size_t(v) + 1]; ++k)
      blocked[std::size_t(fine.neighbour[std::size_t(k)])] = 1;
  }
  return nc;
}

/// The coarse level's graph: cells (fine vertices by their `label`) joined by a fine edge.
void coarse_graph(const LevelMesh& fine, const std::vector<int>& label, int nc, LevelMesh& coarse) {
  const int n = fine.size();
  // Each cell's fine vertices (in index order), then per cell the other cells its vertices'
  // neighbours lie in.
  std::vector<int> cell_start(std::size_t(nc) + 1, 0), cell_vertex(static_cast<std::size_t>(n));
  for (int v = 0; v < n; ++v) ++cell_start[std::size_t(label[std::size_t(v)]) + 1];
  for (int c = 0; c < nc; ++c) cell_start[std::size_t(c) + 1] += cell_start[std::size_t(c)];
  {
    std::vector<int> fill(cell_start.begin(), cell_start.end() - 1);
    for (int v = 0; v < n; ++v)
      cell_vertex[std::size_t(fill[std::size_t(label[std::size_t(v)])]++)] = v;
  }
  gather_sets(
      nc, nc,
      [&](int c) {
        int degrees = 0;
        for (int k = cell_start[std::size_t(c)]; k < cell_start[std::size_t(c) + 1]; ++k) {
          const int v = cell_vertex[std::size_t(k)];
          degrees += fine.start[std::size_t(v) + 1] - fine.start[std::size_t(v)];
        }
        return degrees;
      },
      [&](int c, int* mark, int* out) {
        int count = 0;
        for (int k = cell_start[std::size_t(c)]; k < cell_start[std::size_t(c) + 1]; ++k) {
          const int v = cell_vertex[std::size_t(k)];
          for (int e = fine.start[std::size_t(v)]; e < fine.start[std::size_t(v) + 1]; ++e) {
            const int d = label[std::size_t(fine.neighbour[std::size_t(e)])];
            out[count] = d;
            count += d != c && mark[d] != c;
            mark[d] = c;
          }
        }
        return count;
      },
      coarse.start, coarse.neighbour);
  sort_symmetric_sets(coarse.start, coarse.neighbour);
}

/// The coarse level's triangles: the fine ones with corners in three distinct cells.
void coarse_triangles(const LevelMesh& fine, const std::vector<int>& label, int nc,
                      LevelMesh& coarse) {
  // Triangles with three distinct cells, rotated to start at their smallest index (orientation
  // kept), in the order of their sorted corners; the first of several fine triangles that map to
  // one coarse triangle is kept. They are bucketed by their first corner in fine order, and each
  // bucket (a few triangles) is sorted stably by the other two corners.
  const auto F = fine.triangles.size();
  std::vector<std::array<int, 3>> rotated(F);
  parallel_for_indices(F, 4096, [&](std::size_t f) {
    const auto& t = fine.triangles[f];
    std::array<int, 3> c = {label[std::size_t(t[0])], label[std::size_t(t[1])],
                            label[std::size_t(t[2])]};
    if (c[0] == c[1] || c[1] == c[2] || c[0] == c[2]) {
      rotated[f][0] = -1;
      return;
    }
    const int r = int(std::min_element(c.begin(), c.end()) - c.begin());
    std::rotate(c.begin(), c.begin() + r, c.end());
    rotated[f] = c;
  });
  std::vector<int> first_start(std::size_t(nc) + 1, 0);
  for (const auto& c : rotated)
    if (c[0] >= 0) ++first_start[std::size_t(c[0]) + 1];
  for (int c = 0; c < nc; ++c) first_start[std::size_t(c) + 1] += first_start[std::size_t(c)];
  std::vector<std::array<int, 3>> bucketed(std::size_t(first_start.back()));
  {
    std::vector<int> fill(first_start.begin(), first_start.end() - 1);
    for (const auto& c : rotated)
      if (c[0] >= 0) bucketed[std::size_t(fill[std::size_t(c[0])]++)] = c;
  }
  std::vector<int> kept(std::size_t(nc) + 1, 0);
  parallel_for_indices(nc, 1024, [&](int c) {
    const auto b = bucketed.begin() + first_start[std::size_t(c)];
    const auto e = bucketed.begin() + first_start[std::size_t(c) + 1];
    auto rest = [](const std::array<int, 3>& t) {
      return std::pair{std::min(t[1], t[2]), std::max(t[1], t[2])};
    };
    for (auto i = b; i != e; ++i)  // stable insertion sort
      for (auto j = i; j != b && rest(*j) < rest(*(j - 1)); --j) std::iter_swap(j, j - 1);
    auto out = b;
    for (auto i = b; i != e; ++i)
      if (i == b || rest(*i) != rest(*(i - 1))) *out++ = *i;
    kept[std::size_t(c) + 1] = int(out - b);
  });
  for (int c = 0; c < nc; ++c) kept[std::size_t(c) + 1] += kept[std::size_t(c)];
  coarse.triangles.resize(std::size_t(kept.back()));
  parallel_for_indices(nc, 1024, [&](int c) {
    std::copy_n(bucketed.begin() + first_start[std::size_t(c)],
                kept[std::size_t(c) + 1] - kept[std::size_t(c)],
                coarse.triangles.begin() + kept[std::size_t(c)]);
  });
}

/// Step 4: the prolongation (fine x coarse): each fine vertex of the set takes its coarse vertex,
/// each other one the barycentric weights of the coarse triangle it lies in best.
SparseMatrix prolongation(const LevelMesh& fine, const LevelMesh& coarse,
                          const std::vector<int>& coarse_index, const std::vector<int>& label) {
  const int n = fine.size(), nc = coarse.size();
  // Triangles around each coarse vertex.
  std::vector<int> tri_start(std::size_t(nc) + 1, 0), tri_of;
  for (const auto& t : coarse.triangles)
    for (int c : t) ++tri_start[std::size_t(c) + 1];
  for (int c = 0; c < nc; ++c) tri_start[std::size_t(c) + 1] += tri_start[std::size_t(c)];
  tri_of.resize(std::size_t(tri_start.back()));
  {
    std::vector<int> fill(tri_start.begin(), tri_start.end() - 1);
    for (std::size_t t = 0; t < coarse.triangles.size(); ++t)
      for (int c : coarse.triangles[t]) tri_of[std::size_t(fill[std::size_t(c)]++)] = int(t);
  }
  // 4. Prolongation: each row's columns and weights (at most three; column -1 unused), found in
  // parallel (a row by one task), then gathered into compressed columns in row order.
  std::vector<std::array<int, 3>> row_column(static_cast<std::size_t>(n));
  std::vector<std::array<double, 3>> row_weight(static_cast<std::size_t>(n));
  parallel_for_indices(n, 1024, [&](int v) {
    std::array<int, 3>& columns = row_column[std::size_t(v)];
    std::array<double, 3>& weights = row_weight[std::size_t(v)];
    const int s = label[std::size_t(v)];
    columns = {s, -1, -1};
    weights = {1.0, 0.0, 0.0};
    if (coarse_index[std::size_t(v)] >= 0) return;
    double best = -std::numeric_limits<double>::infinity();
    std::array<double, 3> best_w{};
    int best_t = -1;
    auto consider = [&](int c) {
      for (int k = tri_start[std::size_t(c)]; k < tri_start[std::size_t(c) + 1]; ++k) {
        const int tk = tri_of[std::size_t(k)];
        const auto& t = coarse.triangles[std::size_t(tk)];
        std::array<double, 3> w;
        if (!barycentric(fine.points.row(v), coarse.points.row(t[0]), coarse.points.row(t[1]),
                         coarse.points.row(t[2]), w))
          continue;
        const double score = std::min({w[0], w[1], w[2]});
        if (score > best) {
          best = score;
          best_w = w;
          best_t = tk;
        }
      }
    };
    consider(s);
    // Outside every triangle around its own sample (a cell that reaches past them): the
    // triangles around the cells its neighbours belong to, which lie next to it.
    if (best < 0)
      for (int k = fine.start[std::size_t(v)]; k < fine.start[std::size_t(v) + 1]; ++k) {
        const int c = label[std::size_t(fine.neighbour[std::size_t(k)])];
        if (c != s) consider(c);
      }
    if (best_t < 0) return;
    double sum = 0;
    for (double& w : best_w) sum += (w = std::max(w, 0.0));
    const auto& t = coarse.triangles[std::size_t(best_t)];
    int kept = 0;
    for (int c = 0; c < 3; ++c)
      if (best_w[std::size_t(c)] > 0) {
        columns[std::size_t(kept)] = t[std::size_t(c)];
        weights[std::size_t(kept++)] = best_w[std::size_t(c)] / sum;
      }
    for (; kept < 3; ++kept) columns[std::size_t(kept)] = -1;
  });
  SparseMatrix P(n, nc);
  {
    int* outer = P.outerIndexPtr();
    for (const auto& columns : row_column)
      for (int c : columns)
        if (c >= 0) ++outer[c + 1];
    for (int c = 0; c < nc; ++c) outer[c + 1] += outer[c];
    P.resizeNonZeros(outer[nc]);
    std::vector<int> fill(outer, outer + nc);
    for (int v = 0; v < n; ++v)
      for (int k = 0; k < 3; ++k) {
        const int c = row_column[std::size_t(v)][std::size_t(k)];
        if (c < 0) continue;
        const int e = fill[std::size_t(c)]++;
        P.innerIndexPtr()[e] = v;
        P.valuePtr()[e] = row_weight[std::size_t(v)][std::size_t(k)];
      }
  }
  return P;
}

/// One coarsening step (header, steps 1-4): the coarse level and the prolongation (fine x coarse).
std::pair<LevelMesh, SparseMatrix> coarsen(const LevelMesh& fine) {
  const int n = fine.size();
  std::vector<int> coarse_index(std::size_t(n), -1);
  const int nc = independent_set(fine, coarse_index);
  // 2. Graph Voronoi cells.
  const std::vector<int> label =
      graph_voronoi_cells(fine.start, fine.neighbour, fine.points, coarse_index);
  // 3. The coarse level: the set's points, the cells' graph and triangles.
  LevelMesh coarse;
  coarse.points.resize(nc, 3);
  for (int v = 0; v < n; ++v)
    if (coarse_index[std::size_t(v)] >= 0)
      coarse.points.row(coarse_index[std::size_t(v)]) = fine.points.row(v);
  coarse_graph(fine, label, nc, coarse);
  coarse_triangles(fine, label, nc, coarse);
  SparseMatrix P = prolongation(fine, coarse, coarse_index, label);
  return {std::move(coarse), std::move(P)};
}

/// The symmetric pattern (ones) of a level's graph with its diagonal, written straight into the
/// compressed arrays (each column: the neighbours below, the vertex, the neighbours above; sorted,
/// as the graph's rows are).
SparseMatrix graph_pattern(const LevelMesh& level) {
  const int n = level.size();
  SparseMatrix A(n, n);
  A.resizeNonZeros(Eigen::Index(level.neighbour.size()) + n);
  int* outer = A.outerIndexPtr();
  int* inner = A.innerIndexPtr();
  for (int v = 0; v <= n; ++v) outer[v] = level.start[std::size_t(v)] + v;
  parallel_for_indices(n, 4096, [&](int v) {
    int* out = inner + outer[v];
    const int* b = level.neighbour.data() + level.start[std::size_t(v)];
    const int* e = level.neighbour.data() + level.start[std::size_t(v) + 1];
    const int* mid = std::lower_bound(b, e, v);
    out = std::copy(b, mid, out);
    *out++ = v;
    std::copy(mid, e, out);
  });
  std::fill(A.valuePtr(), A.valuePtr() + A.nonZeros(), 1.0);
  return A;
}

std::vector<std::uint8_t> solver_colours(const SparseMatrix& pattern) {
  int count = 0;
  const std::vector<int> c = greedy_colouring(pattern, &count);
  if (count > 8) return {};
  return std::vector<std::uint8_t>(c.begin(), c.end());
}

}  // namespace

std::vector<int> greedy_colouring(const SparseMatrix& A, int* count) {
  if (!A.isCompressed()) {
    SparseMatrix compressed = A;
    compressed.makeCompressed();
    return greedy_colouring(compressed, count);
  }
  const int n = int(A.cols());
  const int* outer = A.outerIndexPtr();
  const int* inner = A.innerIndexPtr();
  std::vector<int> degree(static_cast<std::size_t>(n), 0);
  for (int j = 0; j < n; ++j)
    for (int k = outer[j]; k < outer[j + 1]; ++k)
      if (inner[k] != j) ++degree[std::size_t(j)];
  // Smallest-last order: repeatedly remove a vertex of least remaining degree (lazy buckets: a
  // vertex is pushed again whenever its degree drops, stale entries are skipped). The vertices
  // visit the pattern in no local order: the columns of the vertices just pushed, the likeliest
  // to be removed next, are fetched ahead.
  const int max_degree = n ? *std::max_element(degree.begin(), degree.end()) : 0;
  std::vector<std::vector<int>> bucket(std::size_t(max_degree) + 1);
  for (int v = n - 1; v >= 0; --v) bucket[std::size_t(degree[std::size_t(v)])].push_back(v);
  std::vector<char> removed(static_cast<std::size_t>(n), 0);
  std::vector<int> order;
  order.reserve(std::size_t(n));
  int low = 0;
  while (int(order.size()) < n) {
    while (bucket[std::size_t(low)].empty()) ++low;
    const int v = bucket[std::size_t(low)].back();
    bucket[std::size_t(low)].pop_back();
    if (removed[std::size_t(v)] || degree[std::size_t(v)] != low) continue;
    removed[std::size_t(v)] = 1;
    order.push_back(v);
    for (int k = outer[v]; k < outer[v + 1]; ++k) {
      const int w = inner[k];
      if (w == v || removed[std::size_t(w)]) continue;
      __builtin_prefetch(inner + outer[w]);
      bucket[std::size_t(--degree[std::size_t(w)])].push_back(w);
    }
    low = std::max(0, low - 1);
  }
  // Greedy colours in the reverse order, which is known: each vertex's column is fetched a few
  // vertices ahead, and its neighbours' colours a few after that.
  std::vector<int> colour(static_cast<std::size_t>(n), -1);
  std::vector<int> used_by(std::size_t(max_degree) + 2, -1);  // colour -> last vertex that saw it
  int colours = 0;
  constexpr int ahead = 8;
  for (int i = n - 1; i >= 0; --i) {
    if (i >= 2 * ahead) __builtin_prefetch(inner + outer[order[std::size_t(i - 2 * ahead)]]);
    if (i >= ahead) {
      const int u = order[std::size_t(i - ahead)];
      for (int k = outer[u]; k < outer[u + 1]; ++k)
        __builtin_prefetch(&colour[std::size_t(inner[k])]);
    }
    const int v = order[std::size_t(i)];
    for (int k = outer[v]; k < outer[v + 1]; ++k) {
      const int w = inner[k];
      if (w != v && colour[std::size_t(w)] >= 0) used_by[std::size_t(colour[std::size_t(w)])] = v;
    }
    int c = 0;
    while (used_by[std::size_t(c)] == v) ++c;
    colour[std::size_t(v)] = c;
    colours = std::max(colours, c + 1);
  }
  if (count) *count = colours;
  return colour;
}

SurfaceHierarchy build_surface_hierarchy(const Positions& vertices, const Triangles& faces,
                                         const SurfaceHierarchyOptions& options) {
  std::vector<LevelMesh> levels;  // finest first while building
  std::vector<SparseMatrix> P;    // P[k]: level k (fine) x level k+1 (coarse)
  levels.push_back(finest_level(vertices, faces));
  while (levels.back().size() > options.coarsest_size && int(levels.size()) < options.max_levels) {
    auto [coarse, prolongation] = coarsen(levels.back());
    if (coarse.size() > 0.9 * levels.back().size()) break;  // no longer shrinking
    levels.push_back(std::move(coarse));
    P.push_back(std::move(prolongation));
  }
  // Colourings of the Galerkin patterns, finest first.
  std::vector<std::vector<std::uint8_t>> colours(levels.size());
  SparseMatrix pattern = graph_pattern(levels.front());
  colours[0] = solver_colours(pattern);
  for (std::size_t k = 0; k < P.size(); ++k) {
    pattern = galerkin_pattern(P[k], pattern);
    colours[k + 1] = solver_colours(pattern);
  }
  SurfaceHierarchy h;
  for (auto it = levels.rbegin(); it != levels.rend(); ++it)
    h.points.push_back(std::move(it->points));
  for (auto it = P.rbegin(); it != P.rend(); ++it) h.prolongations.push_back(std::move(*it));
  h.colours.assign(colours.rbegin(), colours.rend());
  return h;
}

}  // namespace mcf
