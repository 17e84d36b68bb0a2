// The hat basis's multigrid hierarchy (bases/surface_hierarchy.h): prolongations reproduce
// constants everywhere and linear functions on a flat mesh, a 1-to-4 subdivided mesh coarsens back
// to its coarse vertices, levels shrink to the coarsest size, colourings are valid on the patterns
// the Galerkin matrices will have, and the build is deterministic.

#include "bases/hat_basis.h"
#include "bases/surface_hierarchy.h"
#include "bases/vertex_ordering.h"
#include "core/galerkin_pattern.h"
#include "datasets/mesh_spec.h"

#include "test_meshes.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <queue>
#include <tuple>

namespace mcf {
namespace {

/// An n x n grid of squares on [0,1]^2 (z = 0), each split into two triangles along alternating
/// diagonals, its vertices numbered in a shuffled order (so nothing depends on a lexicographic
/// one).
TriangleMesh flat_grid(int n) {
  const int nv = (n + 1) * (n + 1);
  std::vector<int> order(static_cast<std::size_t>(nv));
  for (int i = 0; i < nv; ++i) order[std::size_t(i)] = int((std::int64_t(i) * 7919) % nv);
  TriangleMesh m;
  m.vertices.resize(nv, 3);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      m.vertices.row(order[std::size_t(j * (n + 1) + i)]) << double(i) / n, double(j) / n, 0.0;
  m.faces.resize(2 * n * n, 3);
  int f = 0;
  auto id = [&](int i, int j) { return order[std::size_t(j * (n + 1) + i)]; };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      if ((i + j) % 2 == 0) {
        m.faces.row(f++) << id(i, j), id(i + 1, j), id(i + 1, j + 1);
        m.faces.row(f++) << id(i, j), id(i + 1, j + 1), id(i, j + 1);
      } else {
        m.faces.row(f++) << id(i, j), id(i + 1, j), id(i, j + 1);
        m.faces.row(f++) << id(i + 1, j), id(i + 1, j + 1), id(i, j + 1);
      }
    }
  return m;
}

/// Pattern (ones) of the mesh's vertex adjacency with the diagonal: the hat basis's matrices'.
SparseMatrix adjacency(const TriangleMesh& m) {
  std::vector<Eigen::Triplet<double, int>> t;
  for (Eigen::Index f = 0; f < m.faces.rows(); ++f)
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) t.emplace_back(m.faces(f, a), m.faces(f, b), 1.0);
  SparseMatrix A(m.vertices.rows(), m.vertices.rows());
  A.setFromTriplets(t.begin(), t.end());
  for (int k = 0; k < A.outerSize(); ++k)
    for (SparseMatrix::InnerIterator it(A, k); it; ++it) it.valueRef() = 1.0;
  return A;
}

void expect_valid_colouring(const SparseMatrix& pattern, const std::vector<std::uint8_t>& c) {
  ASSERT_EQ(Eigen::Index(c.size()), pattern.rows());
  for (int j = 0; j < pattern.outerSize(); ++j)
    for (SparseMatrix::InnerIterator it(pattern, j); it; ++it) {
      if (it.row() != j) {
        ASSERT_NE(c[std::size_t(it.row())], c[std::size_t(j)]) << it.row() << " " << j;
      }
    }
}

TEST(SurfaceHierarchy, ProlongationRowsSumToOneAndLevelsShrink) {
  for (const char* spec : {"torus", "dumbbell", "cgal:armadillo"}) {
    const TriangleMesh m = load_mesh_spec(spec).mesh;
    const SurfaceHierarchy h = build_surface_hierarchy(m.vertices, m.faces, {500, 16});
    ASSERT_GE(h.levels(), 2) << spec;
    EXPECT_LE(h.points.front().rows(), 500) << spec;
    EXPECT_EQ(h.points.back().rows(), m.vertices.rows());
    for (std::size_t l = 0; l < h.prolongations.size(); ++l) {
      const SparseMatrix& P = h.prolongations[l];
      ASSERT_EQ(P.rows(), h.points[l + 1].rows());
      ASSERT_EQ(P.cols(), h.points[l].rows());
      // Coarsening by an independent set of the vertex graph keeps 1/7 to 1/3 of the vertices.
      EXPECT_GT(double(P.rows()) / double(P.cols()), 3.0) << spec << " level " << l;
      EXPECT_LT(double(P.rows()) / double(P.cols()), 7.0) << spec << " level " << l;
      const Eigen::VectorXd ones = P * Eigen::VectorXd::Ones(P.cols());
      EXPECT_LT((ones.array() - 1.0).abs().maxCoeff(), 1e-12) << spec << " level " << l;
      for (int k = 0; k < P.outerSize(); ++k)
        for (SparseMatrix::InnerIterator it(P, k); it; ++it) ASSERT_GT(it.value(), 0.0);
      // A coarse vertex is one of the finer level's, at its own position.
      const Eigen::MatrixXd moved = P * h.points[l];
      int exact = 0;
      for (Eigen::Index i = 0; i < P.rows(); ++i)
        exact += (moved.row(i) - h.points[l + 1].row(i)).norm() == 0.0;
      EXPECT_GE(exact, P.cols()) << spec << " level " << l;
    }
  }
}

TEST(SurfaceHierarchy, LinearFunctionsAreReproducedOnAFlatMesh) {
  const TriangleMesh m = flat_grid(60);
  const SurfaceHierarchy h = build_surface_hierarchy(m.vertices, m.faces, {100, 16});
  ASSERT_GE(h.levels(), 3);
  const Eigen::Vector3d g(0.7, -1.3, 0.0);
  for (std::size_t l = 0; l < h.prolongations.size(); ++l) {
    const Eigen::VectorXd coarse = h.points[l] * g, fine = h.points[l + 1] * g;
    const Eigen::VectorXd interpolated = h.prolongations[l] * (coarse.array() + 0.25).matrix();
    // Away from the boundary every vertex lies inside a coarse triangle around its cell's sample.
    int checked = 0;
    for (Eigen::Index i = 0; i < fine.size(); ++i) {
      const Eigen::RowVector3d p = h.points[l + 1].row(i);
      // Three of the finer level's spacings: the coarse triangles cover the square up to there.
      const double margin = 3.0 / std::sqrt(double(fine.size()));
      if (p.x() < margin || p.y() < margin || p.x() > 1 - margin || p.y() > 1 - margin) continue;
      EXPECT_NEAR(interpolated[i], fine[i] + 0.25, 1e-12) << "level " << l << " vertex " << i;
      ++checked;
    }
    EXPECT_GT(checked, fine.size() / 5) << "level " << l;
  }
}

TEST(SurfaceHierarchy, ASubdividedMeshCoarsensBackToItsCoarseVertices) {
  // test_icosphere numbers the vertices of each subdivision after those of the one before: the
  // greedy independent set in index order picks exactly the coarser icosphere's vertices.
  const TriangleMesh fine = test_icosphere(5), coarse = test_icosphere(4);
  const SurfaceHierarchy h = build_surface_hierarchy(fine.vertices, fine.faces, {3000, 2});
  ASSERT_EQ(h.levels(), 2);
  ASSERT_EQ(h.points[0].rows(), coarse.vertices.rows());
  EXPECT_EQ((h.points[0] - coarse.vertices).cwiseAbs().maxCoeff(), 0.0);
  // Each new vertex is the midpoint of its edge, projected: half and half of the two ends.
  const SparseMatrix& P = h.prolongations[0];
  for (Eigen::Index i = coarse.vertices.rows(); i < P.rows(); ++i) {
    std::vector<double> w;
    for (int k = 0; k < P.outerSize(); ++k)
      for (SparseMatrix::InnerIterator it(P, k); it; ++it)
        if (it.row() == i) w.push_back(it.value());
    // On the sphere the midpoint lies off the coarse triangles' planes: its projection is half way
    // along the edge up to the curvature's share.
    ASSERT_GE(w.size(), 2u) << i;
    std::sort(w.rbegin(), w.rend());
    EXPECT_NEAR(w[0], 0.5, 1e-3) << i;
    EXPECT_NEAR(w[1], 0.5, 1e-3) << i;
    if (i > coarse.vertices.rows() + 200) break;  // rows are in column storage: a sample suffices
  }
}

TEST(SurfaceHierarchy, ColouringsAreValidOnTheGalerkinPatterns) {
  const TriangleMesh m = load_mesh_spec("cgal:armadillo").mesh;
  const SurfaceHierarchy h = build_surface_hierarchy(m.vertices, m.faces, {500, 16});
  SparseMatrix pattern = adjacency(m);
  int coloured = 0;
  for (int l = h.levels() - 1; l >= 0; --l) {
    if (!h.colours[std::size_t(l)].empty()) {
      expect_valid_colouring(pattern, h.colours[std::size_t(l)]);
      for (std::uint8_t c : h.colours[std::size_t(l)]) ASSERT_LT(c, 8);
      ++coloured;
    }
    if (l > 0) {
      const SparseMatrix& P = h.prolongations[std::size_t(l - 1)];
      pattern = SparseMatrix(P.transpose()) * pattern * P;
    }
  }
  // A triangle mesh's graph is planar, so smallest-last greedy colours it with at most six.
  int count = 0;
  greedy_colouring(adjacency(m), &count);
  EXPECT_LE(count, 6);
  EXPECT_FALSE(h.colours.back().empty());
  EXPECT_GE(coloured, 1);
}

/// The vertex graph of a mesh in compressed rows (sorted, no self loops).
void vertex_graph(const TriangleMesh& m, std::vector<int>& start, std::vector<int>& neighbour) {
  const int n = int(m.vertices.rows());
  std::vector<std::vector<int>> adj(static_cast<std::size_t>(n));
  for (Eigen::Index f = 0; f < m.faces.rows(); ++f)
    for (int c = 0; c < 3; ++c) {
      const int a = m.faces(f, c), b = m.faces(f, (c + 1) % 3);
      adj[std::size_t(a)].push_back(b);
      adj[std::size_t(b)].push_back(a);
    }
  start.assign(1, 0);
  neighbour.clear();
  for (auto& a : adj) {
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
    neighbour.insert(neighbour.end(), a.begin(), a.end());
    start.push_back(int(neighbour.size()));
  }
}

/// The graph distances of every vertex to its nearest sample and that sample's label: Dijkstra
/// from every sample at once on (distance, sample index), the definition of the Voronoi cells.
struct DijkstraCells {
  std::vector<double> distance;
  std::vector<int> label;
};

DijkstraCells dijkstra(const std::vector<int>& start, const std::vector<int>& neighbour,
                       const Positions& p, const std::vector<int>& sample) {
  const std::size_t n = std::size_t(p.rows());
  DijkstraCells r{std::vector<double>(n, std::numeric_limits<double>::infinity()),
                  std::vector<int>(n, std::numeric_limits<int>::max())};
  using Entry = std::tuple<double, int, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> queue;
  for (std::size_t v = 0; v < n; ++v)
    if (sample[v] >= 0) {
      r.distance[v] = 0;
      r.label[v] = sample[v];
      queue.emplace(0.0, sample[v], int(v));
    }
  while (!queue.empty()) {
    const auto [d, lab, v] = queue.top();
    queue.pop();
    if (d != r.distance[std::size_t(v)] || lab != r.label[std::size_t(v)]) continue;
    for (int k = start[std::size_t(v)]; k < start[std::size_t(v) + 1]; ++k) {
      const int w = neighbour[std::size_t(k)];
      const double nd = d + (p.row(v) - p.row(w)).norm();
      if (std::tie(nd, lab) < std::tie(r.distance[std::size_t(w)], r.label[std::size_t(w)])) {
        r.distance[std::size_t(w)] = nd;
        r.label[std::size_t(w)] = lab;
        queue.emplace(nd, lab, w);
      }
    }
  }
  return r;
}

/// Whether `cells` are graph Voronoi cells of `sample`: every vertex whose label differs from
/// Dijkstra's lies, along the graph, as near its own label's sample as Dijkstra's nearest one, up
/// to rounding (1e-12 relative). Edge lengths summed in another order, or contracted into fused
/// multiply-adds by another compiler's flags, move ties of equal paths (a grid's) by an ulp, so
/// which of two tied samples wins is not a property of the cells; everything else is.
::testing::AssertionResult are_voronoi_cells(const std::vector<int>& cells,
                                             const DijkstraCells& reference,
                                             const std::vector<int>& start,
                                             const std::vector<int>& neighbour, const Positions& p,
                                             const std::vector<int>& sample) {
  const std::size_t n = std::size_t(p.rows());
  if (cells.size() != n) return ::testing::AssertionFailure() << "size " << cells.size();
  std::vector<int> sample_vertex;
  for (std::size_t v = 0; v < n; ++v)
    if (sample[v] >= 0) {
      if (std::size_t(sample[v]) >= sample_vertex.size())
        sample_vertex.resize(std::size_t(sample[v]) + 1, -1);
      sample_vertex[std::size_t(sample[v])] = int(v);
    }
  std::map<int, std::vector<double>> from;  // single-source distances of a differing label
  int differing = 0;
  for (std::size_t v = 0; v < n; ++v) {
    const int lab = cells[v];
    if (lab == reference.label[v]) continue;
    ++differing;
    if (lab < 0 || std::size_t(lab) >= sample_vertex.size())
      return ::testing::AssertionFailure() << "vertex " << v << ": label " << lab;
    auto it = from.find(lab);
    if (it == from.end()) {
      std::vector<int> one(n, -1);
      one[std::size_t(sample_vertex[std::size_t(lab)])] = 0;
      it = from.emplace(lab, dijkstra(start, neighbour, p, one).distance).first;
    }
    const double own = it->second[v], best = reference.distance[v];
    if (!(std::abs(own - best) <= 1e-12 * std::max(1.0, best)))
      return ::testing::AssertionFailure()
             << "vertex " << v << " in the cell of sample " << lab << " at distance " << own
             << ", Dijkstra's nearest is sample " << reference.label[v] << " at " << best;
  }
  // Ties decide a few labels, not a region.
  if (differing > int(n / 10))
    return ::testing::AssertionFailure() << differing << " of " << n << " labels differ";
  return ::testing::AssertionSuccess();
}

/// Samples at every `stride`-th vertex from `offset` (indices in vertex order).
std::vector<int> every(int n, int stride, int offset) {
  std::vector<int> sample(static_cast<std::size_t>(n), -1);
  int c = 0;
  for (int v = offset; v < n; v += stride) sample[std::size_t(v)] = c++;
  return sample;
}

// The parallel sweeps find Dijkstra's cells: with ties (a grid's equal edges), with cells many
// hops wide (few samples: the sweeps give up and Dijkstra decides), with coincident points
// (zero-length edges); and the same cells on one thread as on all, bitwise.
TEST(SurfaceHierarchy, GraphVoronoiCellsAreDijkstras) {
  struct Case {
    TriangleMesh mesh;
    const char* name;
  };
  std::vector<Case> cases;
  cases.push_back({flat_grid(40), "grid"});
  cases.push_back({load_mesh_spec("cgal:armadillo").mesh, "armadillo"});
  {
    // The grid with its first vertex's point copied onto its neighbours in the first face.
    TriangleMesh m = flat_grid(20);
    m.vertices.row(m.faces(0, 1)) = m.vertices.row(m.faces(0, 0));
    m.vertices.row(m.faces(0, 2)) = m.vertices.row(m.faces(0, 0));
    cases.push_back({m, "coincident"});
  }
  for (const Case& c : cases) {
    std::vector<int> start, neighbour;
    vertex_graph(c.mesh, start, neighbour);
    const int n = int(c.mesh.vertices.rows());
    for (const auto& [stride, offset] : {std::pair{2, 0}, {5, 1}, {7, 3}, {n / 3, 0}, {n, 0}}) {
      const std::vector<int> sample = every(n, stride, offset);
      const DijkstraCells reference = dijkstra(start, neighbour, c.mesh.vertices, sample);
      const std::vector<int> cells = graph_voronoi_cells(start, neighbour, c.mesh.vertices, sample);
      EXPECT_TRUE(are_voronoi_cells(cells, reference, start, neighbour, c.mesh.vertices, sample))
          << c.name << " stride " << stride;
      // The check catches a vertex moved to a far cell: sample 0's own vertex given the last's.
      std::vector<int> moved = cells;
      const int first = int(std::find(sample.begin(), sample.end(), 0) - sample.begin());
      moved[std::size_t(first)] = *std::max_element(sample.begin(), sample.end());
      if (moved[std::size_t(first)] != 0) {
        EXPECT_FALSE(are_voronoi_cells(moved, reference, start, neighbour, c.mesh.vertices, sample))
            << c.name << " stride " << stride;
      }
      tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
      EXPECT_EQ(graph_voronoi_cells(start, neighbour, c.mesh.vertices, sample), cells)
          << c.name << " stride " << stride << ", one thread";
    }
  }
}

// The Galerkin pattern the colourings are computed on (core/galerkin_pattern.h) is the pattern of
// Eigen's numeric product, level by level, with sorted row indices, on one thread as on all.
TEST(SurfaceHierarchy, GalerkinPatternIsTheProductsPattern) {
  const TriangleMesh m = load_mesh_spec("cgal:armadillo").mesh;
  const SurfaceHierarchy h = build_surface_hierarchy(m.vertices, m.faces, {200, 16});
  ASSERT_GE(h.levels(), 3);
  SparseMatrix pattern = adjacency(m);
  for (int l = h.levels() - 1; l > 0; --l) {
    const SparseMatrix& P = h.prolongations[std::size_t(l - 1)];
    SparseMatrix product = SparseMatrix(P.transpose()) * pattern * P;
    product.makeCompressed();
    const SparseMatrix symbolic = galerkin_pattern(P, pattern);
    const SparseMatrix serial = [&] {
      tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
      return galerkin_pattern(P, pattern);
    }();
    ASSERT_TRUE(symbolic.isCompressed());
    ASSERT_EQ(symbolic.rows(), product.rows());
    ASSERT_EQ(symbolic.cols(), product.cols());
    ASSERT_EQ(symbolic.nonZeros(), product.nonZeros()) << "level " << l;
    EXPECT_TRUE(std::equal(symbolic.outerIndexPtr(), symbolic.outerIndexPtr() + P.cols() + 1,
                           product.outerIndexPtr()))
        << "level " << l;
    EXPECT_TRUE(std::equal(symbolic.innerIndexPtr(), symbolic.innerIndexPtr() + product.nonZeros(),
                           product.innerIndexPtr()))
        << "level " << l;
    EXPECT_TRUE(std::equal(serial.innerIndexPtr(), serial.innerIndexPtr() + serial.nonZeros(),
                           symbolic.innerIndexPtr()))
        << "level " << l;
    for (Eigen::Index k = 0; k < symbolic.nonZeros(); ++k) ASSERT_EQ(symbolic.valuePtr()[k], 0.0);
    pattern = product;
  }
}

// The same hierarchy twice, and on one thread as on all (the prolongation rows are found in
// parallel).
TEST(SurfaceHierarchy, TheBuildIsDeterministic) {
  const TriangleMesh m = load_mesh_spec("dumbbell").mesh;
  const SurfaceHierarchy a = build_surface_hierarchy(m.vertices, m.faces, {300, 16});
  const SurfaceHierarchy b = [&] {
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    return build_surface_hierarchy(m.vertices, m.faces, {300, 16});
  }();
  ASSERT_EQ(a.levels(), b.levels());
  EXPECT_EQ(a.colours, b.colours);
  for (std::size_t l = 0; l < a.prolongations.size(); ++l) {
    const SparseMatrix d = a.prolongations[l] - b.prolongations[l];
    EXPECT_EQ(d.norm(), 0.0) << l;
  }
}

/// The largest |number(i) - number(j)| over the mesh's edges under `rank` (vertex -> number).
int bandwidth(const Triangles& F, const std::vector<int>& rank) {
  int b = 0;
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int c = 0; c < 3; ++c)
      b = std::max(b, std::abs(rank[std::size_t(F(f, c))] - rank[std::size_t(F(f, (c + 1) % 3))]));
  return b;
}

TEST(VertexOrdering, APermutationWithASmallBandwidth) {
  for (const char* spec : {"cgal:armadillo@faces=208000", "sphere:vertices=50000", "torus"}) {
    const TriangleMesh m = load_mesh_spec(spec).mesh;
    const int n = int(m.vertices.rows());
    const std::vector<int> order = bandwidth_ordering(m.faces, n);
    ASSERT_EQ(int(order.size()), n);
    std::vector<int> rank(static_cast<std::size_t>(n), -1), identity(static_cast<std::size_t>(n));
    for (int k = 0; k < n; ++k) {
      ASSERT_EQ(rank[std::size_t(order[std::size_t(k)])], -1) << "twice: " << order[std::size_t(k)];
      rank[std::size_t(order[std::size_t(k)])] = k;
      identity[std::size_t(k)] = k;
    }
    // A breadth-first level of a surface holds about sqrt(n) vertices.
    const int b = bandwidth(m.faces, rank);
    EXPECT_LT(b, 20.0 * std::sqrt(double(n))) << spec;
    EXPECT_LE(b, bandwidth(m.faces, identity)) << spec;
  }
}

/// Cuthill–McKee as the header defines it, written plainly: per component, two breadth-first
/// sweeps to a pseudo-peripheral root, each vertex's new neighbours sorted by (degree, index).
std::vector<int> plain_cuthill_mckee(const TriangleMesh& m) {
  std::vector<int> start, neighbour;
  vertex_graph(m, start, neighbour);
  const int n = int(m.vertices.rows());
  auto degree = [&](int v) { return start[std::size_t(v) + 1] - start[std::size_t(v)]; };
  auto sweep = [&](int root, std::vector<int>& out) {
    std::vector<char> seen(static_cast<std::size_t>(n), 0);
    out = {root};
    seen[std::size_t(root)] = 1;
    for (std::size_t h = 0; h < out.size(); ++h) {
      std::vector<int> next;
      for (int k = start[std::size_t(out[h])]; k < start[std::size_t(out[h]) + 1]; ++k)
        if (!seen[std::size_t(neighbour[std::size_t(k)])]) {
          seen[std::size_t(neighbour[std::size_t(k)])] = 1;
          next.push_back(neighbour[std::size_t(k)]);
        }
      std::sort(next.begin(), next.end(), [&](int a, int b) {
        return std::pair{degree(a), a} < std::pair{degree(b), b};
      });
      out.insert(out.end(), next.begin(), next.end());
    }
  };
  std::vector<int> order, component;
  std::vector<char> numbered(static_cast<std::size_t>(n), 0);
  for (int seed = 0; seed < n; ++seed) {
    if (numbered[std::size_t(seed)] || degree(seed) == 0) continue;
    int root = seed;
    for (int s = 0; s < 3; ++s) {
      sweep(root, component);
      root = component.back();
    }
    for (int v : component) numbered[std::size_t(v)] = 1;
    order.insert(order.end(), component.begin(), component.end());
  }
  for (int v = 0; v < n; ++v)
    if (degree(v) == 0) order.push_back(v);
  return order;
}

TEST(VertexOrdering, IsCuthillMcKeeFromAPseudoPeripheralRoot) {
  for (const char* spec : {"cgal:armadillo", "sphere:vertices=20000", "dumbbell"}) {
    const TriangleMesh m = load_mesh_spec(spec).mesh;
    EXPECT_EQ(bandwidth_ordering(m.faces, int(m.vertices.rows())), plain_cuthill_mckee(m)) << spec;
  }
}

TEST(VertexOrdering, TheHatBasisWithAHierarchyEvaluatesInTheMeshsOrder) {
  const TriangleMesh m = load_mesh_spec("cgal:armadillo").mesh;
  const HatBasis plain(m), ordered(m, MassKind::consistent, SurfaceHierarchyOptions{});
  EXPECT_EQ(plain.evaluate_vertices(plain.initial_coefficients()), m.vertices);
  EXPECT_EQ(ordered.evaluate_vertices(ordered.initial_coefficients()), m.vertices);
  EXPECT_NE(ordered.initial_coefficients(), m.vertices);  // renumbered
  // The same operator in another numbering: the energies of the embedding agree.
  const Coefficients x0 = plain.initial_coefficients(), y0 = ordered.initial_coefficients();
  const double ep = (x0.transpose() * (SparseMatrix(plain.stiffness()) * x0)).trace();
  const double eo = (y0.transpose() * (SparseMatrix(ordered.stiffness()) * y0)).trace();
  EXPECT_NEAR(ep, eo, 1e-10 * ep);
}

}  // namespace
}  // namespace mcf
