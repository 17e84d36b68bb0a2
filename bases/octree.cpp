#include "bases/octree.h"

#include "core/parallel.h"
#include "datasets/referenced_vertices.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace mcf {

GridCube choose_cube(const TriangleMesh& mesh, int depth, OctreeCube cube) {
  if (depth < 1 || depth > 20)
    throw std::invalid_argument("octree depth must be in [1,20], got " + std::to_string(depth));
  if (mesh.num_vertices() == 0) throw std::invalid_argument("choose_cube: empty mesh");
  const Bounds bounds = surface_bounds(mesh);
  const Eigen::Vector3d lo = bounds.lo.transpose(), hi = bounds.hi.transpose();
  const bool fits = (lo.array() >= 0.0).all() && (hi.array() <= 1.0).all();
  GridCube g;
  g.depth = depth;
  if (cube == OctreeCube::unit || (cube == OctreeCube::automatic && fits)) {
    if (!fits) {
      std::ostringstream what;
      what << "octree cube \"unit\" (octree.cube, --cube): the mesh's bounding box ["
           << lo.transpose() << "] - [" << hi.transpose()
           << "] does not lie inside the unit cube [0, 1]^3; use \"auto\" or \"tight\"";
      throw std::invalid_argument(what.str());
    }
    g.origin.setZero();
    g.side = 1.0;
    return g;
  }
  const double extent = (hi - lo).maxCoeff();
  if (!(extent > 0.0) || !std::isfinite(extent))
    throw std::invalid_argument("choose_cube: degenerate or non-finite mesh extent");
  // side = 1.01 extent + one cell (half a cell of margin on each side beyond the 0.5% per side).
  const double side = 1.01 * extent / (1.0 - 1.0 / static_cast<double>(1 << depth));
  g.side = side;
  g.origin = 0.5 * (lo + hi) - Eigen::Vector3d::Constant(0.5 * side);
  return g;
}

namespace {

// res = largest valid index; rows has (res+1)^2 + 1 entries.
int find_key(const std::vector<GridKey>& keys, const std::vector<int>& rows, int i, int j, int k,
             int res) {
  if (i < 0 || j < 0 || k < 0 || i > res || j > res || k > res) return -1;
  const GridKey key = grid_key(i, j, k);
  const std::size_t row =
      static_cast<std::size_t>(k) * static_cast<std::size_t>(res + 1) + static_cast<std::size_t>(j);
  const auto b = keys.begin() + rows[row], e = keys.begin() + rows[row + 1];
  auto it = e - b <= 8 ? std::find(b, e, key) : std::lower_bound(b, e, key);
  return (it != e && *it == key) ? static_cast<int>(it - keys.begin()) : -1;
}

void fill_rows(const std::vector<GridKey>& keys, int n, std::vector<int>& rows) {
  const std::size_t nrows = static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
  rows.assign(nrows + 1, 0);
  for (GridKey key : keys) {
    const auto ijk = grid_index(key);
    ++rows[static_cast<std::size_t>(ijk[2]) * static_cast<std::size_t>(n) +
           static_cast<std::size_t>(ijk[1]) + 1];
  }
  for (std::size_t r = 0; r < nrows; ++r) rows[r + 1] += rows[r];
}

void sort_unique(std::vector<GridKey>& keys) {
  tbb::parallel_sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
}

void fill_functions(OctreeLevel& L) {
  const std::size_t nc = L.cells.size();
  std::vector<GridKey> corners(8 * nc);
  parallel_for_indices<std::size_t>(nc, 4096, [&](std::size_t c) {
    const auto ijk = grid_index(L.cells[c]);
    for (int q = 0; q < 8; ++q) {
      const auto o = corner_offset(q);
      corners[8 * c + q] = grid_key(ijk[0] + o[0], ijk[1] + o[1], ijk[2] + o[2]);
    }
  });
  sort_unique(corners);
  L.functions = std::move(corners);
  fill_rows(L.functions, (1 << L.depth) + 1, L.function_row_start);
  L.cell_functions.resize(nc);
  parallel_for_indices<std::size_t>(nc, 4096, [&](std::size_t c) {
    const auto ijk = grid_index(L.cells[c]);
    for (int q = 0; q < 8; ++q) {
      const auto o = corner_offset(q);
      L.cell_functions[c][q] = L.find_function(ijk[0] + o[0], ijk[1] + o[1], ijk[2] + o[2]);
    }
  });
}

}  // namespace

int OctreeLevel::find_cell(int i, int j, int k) const {
  return find_key(cells, cell_row_start, i, j, k, (1 << depth) - 1);
}
int OctreeLevel::find_function(int i, int j, int k) const {
  return find_key(functions, function_row_start, i, j, k, 1 << depth);
}

Eigen::Matrix<double, Eigen::Dynamic, 3> Octree::function_positions(int level) const {
  const OctreeLevel& L = levels.at(static_cast<std::size_t>(level));
  const double h = cube.cell_size(L.depth);
  Eigen::Matrix<double, Eigen::Dynamic, 3> c(L.num_functions(), 3);
  for (Eigen::Index f = 0; f < L.num_functions(); ++f) {
    const auto ijk = grid_index(L.functions[static_cast<std::size_t>(f)]);
    for (int a = 0; a < 3; ++a) c(f, a) = cube.origin[a] + h * ijk[a];
  }
  return c;
}

Octree build_octree(const GridCube& cube, std::vector<GridKey> finest_cells, int coarsest_depth) {
  Octree t;
  t.cube = cube;
  const int dmin = std::max(0, std::min(coarsest_depth, cube.depth));
  const int nlev = cube.depth - dmin + 1;
  t.levels.resize(static_cast<std::size_t>(nlev));
  sort_unique(finest_cells);
  t.levels.back().depth = cube.depth;
  t.levels.back().cells = std::move(finest_cells);
  fill_rows(t.levels.back().cells, 1 << cube.depth, t.levels.back().cell_row_start);
  for (int l = nlev - 1; l > 0; --l) {
    OctreeLevel& fine = t.levels[static_cast<std::size_t>(l)];
    OctreeLevel& coarse = t.levels[static_cast<std::size_t>(l - 1)];
    coarse.depth = fine.depth - 1;
    std::vector<GridKey> parents(fine.cells.size());
    tbb::parallel_for(std::size_t(0), fine.cells.size(), [&](std::size_t c) {
      const auto ijk = grid_index(fine.cells[c]);
      parents[c] = grid_key(ijk[0] >> 1, ijk[1] >> 1, ijk[2] >> 1);
    });
    sort_unique(parents);
    coarse.cells = std::move(parents);
    fill_rows(coarse.cells, 1 << coarse.depth, coarse.cell_row_start);
    fine.cell_parent.resize(fine.cells.size());
    tbb::parallel_for(std::size_t(0), fine.cells.size(), [&](std::size_t c) {
      const auto ijk = grid_index(fine.cells[c]);
      fine.cell_parent[c] = coarse.find_cell(ijk[0] >> 1, ijk[1] >> 1, ijk[2] >> 1);
    });
  }
  t.levels.front().cell_parent.assign(t.levels.front().cells.size(), -1);
  for (auto& L : t.levels) fill_functions(L);
  return t;
}

}  // namespace mcf
