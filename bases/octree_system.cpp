#include "bases/octree_system.h"

#include "bases/cell_blocks.h"
#include "core/parallel.h"
#include "datasets/referenced_vertices.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace mcf {

std::vector<int> locate_pieces(const Octree& octree, const std::vector<ClippedTriangle>& pieces) {
  const OctreeLevel& L = octree.finest();
  std::vector<int> cell(pieces.size());
  parallel_for_indices<std::size_t>(pieces.size(), 8192, [&](std::size_t p) {
    const auto ijk = grid_index(pieces[p].cell);
    cell[p] = L.find_cell(ijk[0], ijk[1], ijk[2]);
  });
  for (int c : cell)
    if (c < 0) throw std::runtime_error("locate_pieces: a piece lies in an inactive cell");
  return cell;
}

Octree build_octree(const GridCube& cube, const std::vector<ClippedTriangle>& pieces,
                    int coarsest_depth) {
  // Fan triangles of one clipped polygon are consecutive and share a cell: dropping consecutive
  // duplicates first shrinks the sort several times.
  std::vector<GridKey> keys;
  keys.reserve(pieces.size() / 2 + 1);
  for (std::size_t p = 0; p < pieces.size(); ++p)
    if (keys.empty() || keys.back() != pieces[p].cell) keys.push_back(pieces[p].cell);
  return build_octree(cube, std::move(keys), coarsest_depth);
}

namespace {
/// Cells grouped by (tile colour, tile key), ascending cell index inside a tile.
OctreeSystem::CellTiles build_cell_tiles(const OctreeLevel& L) {
  constexpr int kShift = std::countr_zero(unsigned(OctreeSystem::CellTiles::kTileSide));
  static_assert((1 << kShift) == OctreeSystem::CellTiles::kTileSide,
                "tile side must be a power of two");
  const std::size_t nc = L.cells.size();
  // Sort key: colour in the top bits, then the tile's grid key, then the cell index (stable).
  std::vector<std::pair<std::uint64_t, int>> order(nc);
  parallel_for_indices<std::size_t>(nc, 8192, [&](std::size_t c) {
    const auto ijk = grid_index(L.cells[c]);
    const int ti = ijk[0] >> kShift, tj = ijk[1] >> kShift, tk = ijk[2] >> kShift;
    const std::uint64_t colour = std::uint64_t((ti & 1) + 2 * (tj & 1) + 4 * (tk & 1));
    order[c] = {(colour << 60) | grid_key(ti, tj, tk), static_cast<int>(c)};
  });
  tbb::parallel_sort(order.begin(), order.end());  // keys are unique: same order as std::sort
  OctreeSystem::CellTiles t;
  t.cells.resize(nc);
  t.colour_start.fill(0);
  std::uint64_t previous = ~std::uint64_t(0);
  for (std::size_t i = 0; i < nc; ++i) {
    t.cells[i] = order[i].second;
    if (order[i].first != previous) {
      previous = order[i].first;
      t.tile_start.push_back(static_cast<int>(i));
      ++t.colour_start[static_cast<std::size_t>(previous >> 60) + 1];
    }
  }
  t.tile_start.push_back(static_cast<int>(nc));
  for (std::size_t q = 0; q < 8; ++q) t.colour_start[q + 1] += t.colour_start[q];
  return t;
}
}  // namespace

OctreeSystem::OctreeSystem(const Octree& octree, int level,
                           const std::vector<ClippedTriangle>& pieces,
                           const std::vector<int>& piece_finest_cell)
    : octree_(&octree), pieces_(&pieces), level_(level) {
  if (level < 0 || level >= octree.num_levels())
    throw std::invalid_argument("OctreeSystem: bad level");
  const OctreeLevel& L = octree.levels[static_cast<std::size_t>(level)];
  const std::size_t np = pieces.size(), nc = L.cells.size(), nf = L.functions.size();

  // Piece -> cell of this level (follow the parents up from the finest level).
  piece_cell_ = piece_finest_cell;
  for (int l = octree.num_levels() - 1; l > level; --l) {
    const auto& parent = octree.levels[static_cast<std::size_t>(l)].cell_parent;
    tbb::parallel_for(std::size_t(0), np, [&](std::size_t p) {
      piece_cell_[p] = parent[static_cast<std::size_t>(piece_cell_[p])];
    });
  }
  // Pieces grouped by cell (counting sort; stable, so the order inside a cell is triangle order).
  cell_start_.assign(nc + 1, 0);
  for (int c : piece_cell_) ++cell_start_[static_cast<std::size_t>(c) + 1];
  for (std::size_t c = 0; c < nc; ++c) cell_start_[c + 1] += cell_start_[c];
  piece_order_.resize(np);
  {
    std::vector<int> next(cell_start_.begin(), cell_start_.end() - 1);
    for (std::size_t p = 0; p < np; ++p)
      piece_order_[static_cast<std::size_t>(next[static_cast<std::size_t>(piece_cell_[p])]++)] =
          static_cast<int>(p);
  }
  tiles_ = build_cell_tiles(L);

  // Incident cells: function J is corner b of at most one cell, incident[8J+b] (-1 if none).
  std::vector<int> incident(8 * nf, -1);
  parallel_for_indices<std::size_t>(nc, 4096, [&](std::size_t c) {
    for (int b = 0; b < 8; ++b)
      incident[8 * static_cast<std::size_t>(L.cell_functions[c][static_cast<std::size_t>(b)]) +
               static_cast<std::size_t>(b)] = static_cast<int>(c);
  });
  // Pattern: per column J the 27-bit mask of neighbours that share an active cell with J; rows in
  // bit order are in increasing index order (keys are (k,j,i)-lexicographic).
  mask_.assign(nf, 0u);
  outer_.assign(nf + 1, 0);
  std::vector<int>& outer = outer_;
  parallel_for_indices<std::size_t>(nf, 4096, [&](std::size_t J) {
    std::uint32_t m = 0;
    for (int b = 0; b < 8; ++b) {
      if (incident[8 * J + static_cast<std::size_t>(b)] < 0) continue;
      for (int a = 0; a < 8; ++a) m |= 1u << neighbour_bit(a, b);
    }
    mask_[J] = m;
    outer[J + 1] = std::popcount(m);
  });
  for (std::size_t J = 0; J < nf; ++J) outer[J + 1] += outer[J];
  inner_.resize(static_cast<std::size_t>(outer[nf]));
  int* inner = inner_.data();
  parallel_for_indices<std::size_t>(nf, 4096, [&](std::size_t J) {
    int row[27];
    for (int b = 0; b < 8; ++b) {
      const int c = incident[8 * J + static_cast<std::size_t>(b)];
      if (c < 0) continue;
      for (int a = 0; a < 8; ++a)
        row[neighbour_bit(a, b)] =
            L.cell_functions[static_cast<std::size_t>(c)][static_cast<std::size_t>(a)];
    }
    int s = outer[J];
    for (int o = 0; o < 27; ++o) {
      if (!(mask_[J] & (1u << o))) continue;
      inner[s] = row[o];
      ++s;
    }
  });
}

void OctreeSystem::release_pieces() {
  // swap with empty vectors: clear() alone keeps the capacity.
  std::vector<int>().swap(piece_cell_);
  std::vector<int>().swap(piece_order_);
  released_ = true;
}

SparseMatrix OctreeSystem::pattern() const {
  return SparseMatrix(view(std::vector<double>(inner_.size(), 0.0)));
}

void OctreeSystem::assemble(const CubatureRule& rule, std::vector<double>& mass,
                            std::vector<double>& stiffness) const {
  const OctreeLevel& L = octree_->levels[static_cast<std::size_t>(level_)];
  const GridCube& cube = octree_->cube;
  const double h = cube.cell_size(L.depth), inv_h = 1.0 / h;
  // The pieces are held by reference; the tracked basis frees them once it has its own copy.
  if (released_)
    throw std::logic_error(
        "OctreeSystem::assemble: the pieces were released (RebuiltOctreeBasis::release_assembly)");
  // assign, not resize: a rebuild on a new octree reuses the vectors' memory, zeroed.
  mass.assign(inner_.size(), 0.0);
  stiffness.assign(inner_.size(), 0.0);
  double* Mv = mass.data();
  double* Kv = stiffness.data();
  const int nq = rule.size();
  const auto& pieces = *pieces_;

  for_each_tile([&](const int* cells, int n) {
    CellBlocks<true, true> blocks;
    for (int i = 0; i < n; ++i) {
      const int c = cells[i];
      if (i + 2 < n) {  // pieces are in triangle order: prefetch a later cell's pieces
        const auto cn = static_cast<std::size_t>(cells[i + 2]);
        for (int s = cell_start_[cn]; s < cell_start_[cn + 1]; ++s) {
          const char* p = reinterpret_cast<const char*>(
              &pieces[static_cast<std::size_t>(piece_order_[static_cast<std::size_t>(s)])]);
          __builtin_prefetch(p);
          __builtin_prefetch(p + 64);
        }
      }
      blocks.clear();
      const auto ijk = grid_index(L.cells[static_cast<std::size_t>(c)]);
      double cell_origin[3];
      for (int a = 0; a < 3; ++a) cell_origin[a] = cube.origin[a] + h * ijk[a];
      for (int s = cell_start_[static_cast<std::size_t>(c)];
           s < cell_start_[static_cast<std::size_t>(c) + 1]; ++s) {
        const ClippedTriangle& t =
            pieces[static_cast<std::size_t>(piece_order_[static_cast<std::size_t>(s)])];
        // Orthonormal frame of the piece's plane; identity metric: S = w I.
        double f1[3], f2[3];
        const double len = piece_frame(t.corners[0], t.corners[1], t.corners[2], inv_h, f1, f2);
        if (!(len > 0.0)) continue;
        const double area = 0.5 * len;
        for (int q = 0; q < nq; ++q) {
          const auto& bc = rule.points[static_cast<std::size_t>(q)];
          double local[3];
          for (int a = 0; a < 3; ++a) {
            const double x =
                bc[0] * t.corners[0][a] + bc[1] * t.corners[1][a] + bc[2] * t.corners[2][a];
            local[a] = std::clamp((x - cell_origin[a]) * inv_h, 0.0, 1.0);
          }
          const double w = area * rule.weights[static_cast<std::size_t>(q)];
          blocks.add(local, f1, f2, w, w, 0.0, w);
        }
      }
      blocks.finish();
      add_cell_blocks(c, blocks, Mv, Kv);
    }
    return 0LL;
  });
}

std::vector<SparseMatrix> build_prolongations(const Octree& octree) {
  std::vector<SparseMatrix> P;
  for (int l = 0; l + 1 < octree.num_levels(); ++l) {
    const OctreeLevel& C = octree.levels[static_cast<std::size_t>(l)];
    const OctreeLevel& F = octree.levels[static_cast<std::size_t>(l + 1)];
    const std::size_t nc = C.functions.size();
    std::vector<int> rows(27 * nc);
    std::vector<double> vals(27 * nc);
    std::vector<int> count(nc + 1, 0);
    parallel_for_indices<std::size_t>(nc, 2048, [&](std::size_t c) {
      const auto ijk = grid_index(C.functions[c]);
      int n = 0;
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int f = F.find_function(2 * ijk[0] + dx, 2 * ijk[1] + dy, 2 * ijk[2] + dz);
            if (f < 0) continue;
            rows[27 * c + static_cast<std::size_t>(n)] = f;
            vals[27 * c + static_cast<std::size_t>(n)] =
                (dx ? 0.5 : 1.0) * (dy ? 0.5 : 1.0) * (dz ? 0.5 : 1.0);
            ++n;
          }
      count[c + 1] = n;
    });
    for (std::size_t c = 0; c < nc; ++c) count[c + 1] += count[c];
    SparseMatrix M(F.num_functions(), C.num_functions());
    M.resizeNonZeros(count[nc]);
    std::copy(count.begin(), count.end(), M.outerIndexPtr());
    tbb::parallel_for(std::size_t(0), nc, [&](std::size_t c) {
      const int n = count[c + 1] - count[c];
      std::copy_n(rows.begin() + static_cast<std::ptrdiff_t>(27 * c), n,
                  M.innerIndexPtr() + count[c]);
      std::copy_n(vals.begin() + static_cast<std::ptrdiff_t>(27 * c), n, M.valuePtr() + count[c]);
    });
    P.push_back(std::move(M));
  }
  return P;
}

std::vector<std::vector<std::uint8_t>> build_colours(const Octree& octree) {
  std::vector<std::vector<std::uint8_t>> colours;
  for (const auto& L : octree.levels) {
    std::vector<std::uint8_t> c(L.functions.size());
    for (std::size_t f = 0; f < c.size(); ++f) {
      const auto ijk = grid_index(L.functions[f]);
      c[f] = static_cast<std::uint8_t>((ijk[0] & 1) + 2 * (ijk[1] & 1) + 4 * (ijk[2] & 1));
    }
    colours.push_back(std::move(c));
  }
  return colours;
}

PointStencil cell_stencil(const Octree& octree, int level, int cell, const Eigen::Vector3d& p) {
  const OctreeLevel& L = octree.levels[static_cast<std::size_t>(level)];
  const double h = octree.cube.cell_size(L.depth);
  const auto ijk = grid_index(L.cells[static_cast<std::size_t>(cell)]);
  double t[3];
  for (int a = 0; a < 3; ++a)
    t[a] = std::clamp((p[a] - octree.cube.origin[a]) / h - ijk[a], 0.0, 1.0);
  double v[8], g[8][3];
  trilinear_values(t, 1.0 / h, v, g);
  PointStencil s;
  for (int c = 0; c < 8; ++c) {
    s.functions[static_cast<std::size_t>(c)] =
        L.cell_functions[static_cast<std::size_t>(cell)][static_cast<std::size_t>(c)];
    s.weights[static_cast<std::size_t>(c)] = v[c];
  }
  return s;
}

std::vector<PointStencil> point_stencils(const Octree& octree, const Positions& points) {
  const OctreeLevel& L = octree.finest();
  const int level = octree.num_levels() - 1;
  const double h = octree.cube.cell_size();
  const int res = octree.cube.resolution();
  std::vector<PointStencil> out(static_cast<std::size_t>(points.rows()));
  tbb::parallel_for(Eigen::Index(0), points.rows(), [&](Eigen::Index v) {
    // Candidate cells: those whose closed box contains the point (up to a relative 1e-9 of a
    // cell, for points reconstructed with rounding), the floor cell first.
    int lo[3], hi[3], base[3];
    for (int a = 0; a < 3; ++a) {
      const double u = (points(v, a) - octree.cube.origin[a]) / h;
      base[a] = std::clamp(static_cast<int>(std::floor(u)), 0, res - 1);
      lo[a] = std::clamp(static_cast<int>(std::floor(u - 1e-9)), 0, res - 1);
      hi[a] = std::clamp(static_cast<int>(std::floor(u + 1e-9)), 0, res - 1);
    }
    int cell = L.find_cell(base[0], base[1], base[2]);
    for (int k = lo[2]; cell < 0 && k <= hi[2]; ++k)
      for (int j = lo[1]; cell < 0 && j <= hi[1]; ++j)
        for (int i = lo[0]; cell < 0 && i <= hi[0]; ++i) cell = L.find_cell(i, j, k);
    if (cell < 0) {
      // Fallback (e.g. a vertex whose incident faces are all degenerate): the nearest active cell
      // among the 27 around the floor cell; the clamped stencil evaluates at the closest point of
      // it.
      double best = 2.0;  // in cells; farther than one cell counts as "away from every piece"
      for (int k = base[2] - 1; k <= base[2] + 1; ++k)
        for (int j = base[1] - 1; j <= base[1] + 1; ++j)
          for (int i = base[0] - 1; i <= base[0] + 1; ++i) {
            const int c = L.find_cell(i, j, k);
            if (c < 0) continue;
            double d2 = 0.0;
            const int idx[3] = {i, j, k};
            for (int a = 0; a < 3; ++a) {
              const double u = (points(v, a) - octree.cube.origin[a]) / h;
              const double d = u < idx[a] ? idx[a] - u : (u > idx[a] + 1 ? u - idx[a] - 1 : 0.0);
              d2 += d * d;
            }
            if (std::sqrt(d2) < best) {
              best = std::sqrt(d2);
              cell = c;
            }
          }
    }
    if (cell < 0)
      throw std::runtime_error("point_stencils: point " + std::to_string(v) +
                               " lies in no active cell");
    out[static_cast<std::size_t>(v)] = cell_stencil(octree, level, cell, points.row(v).transpose());
  });
  return out;
}

namespace {

Positions evaluate_stencils(const std::vector<PointStencil>& stencils, const Coefficients& x) {
  Positions out(static_cast<Eigen::Index>(stencils.size()), 3);
  tbb::parallel_for(std::size_t(0), stencils.size(), [&](std::size_t v) {
    double p[3] = {0.0, 0.0, 0.0};
    for (int c = 0; c < 8; ++c) {
      const int I = stencils[v].functions[static_cast<std::size_t>(c)];
      const double w = stencils[v].weights[static_cast<std::size_t>(c)];
      for (int a = 0; a < 3; ++a) p[a] += w * x(I, a);
    }
    for (int a = 0; a < 3; ++a) out(static_cast<Eigen::Index>(v), a) = p[a];
  });
  return out;
}

}  // namespace

VertexStencils vertex_stencils(const Octree& octree, const Positions& vertices,
                               const Triangles& faces) {
  const std::vector<char> used = referenced_vertices(vertices.rows(), faces);
  VertexStencils s;
  if (std::find(used.begin(), used.end(), 0) == used.end()) {
    s.used = point_stencils(octree, vertices);
    return s;
  }
  for (std::size_t v = 0; v < used.size(); ++v)
    if (used[v]) s.used_index.push_back(static_cast<int>(v));
  Positions points(static_cast<Eigen::Index>(s.used_index.size()), 3);
  for (std::size_t i = 0; i < s.used_index.size(); ++i)
    points.row(Eigen::Index(i)) = vertices.row(s.used_index[i]);
  s.used = point_stencils(octree, points);
  s.kept = vertices;
  return s;
}

Positions evaluate_vertices(const VertexStencils& stencils, const Coefficients& x) {
  if (stencils.used_index.empty()) return evaluate_stencils(stencils.used, x);
  Positions all = stencils.kept;
  const Positions used = evaluate_stencils(stencils.used, x);
  for (std::size_t i = 0; i < stencils.used_index.size(); ++i)
    all.row(stencils.used_index[i]) = used.row(Eigen::Index(i));
  return all;
}

}  // namespace mcf
