#include "bases/normal_gradient.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <stdexcept>

namespace mcf {

const std::array<std::array<double, 64>, 9>& unit_gradient_tables() {
  static const std::array<std::array<double, 64>, 9> tables = [] {
    std::array<std::array<double, 64>, 9> T{};
    const double g = 0.5 / std::sqrt(3.0);
    const double points[2] = {0.5 - g, 0.5 + g};  // 2-point Gauss on [0,1], weights 1/2
    for (double px : points)
      for (double py : points)
        for (double pz : points) {
          const double t[3] = {px, py, pz};
          double value[8], gradient[8][3];
          trilinear_values(t, 1.0, value, gradient);
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
              for (int a = 0; a < 8; ++a)
                for (int b = 0; b < 8; ++b)
                  T[std::size_t(3 * i + j)][std::size_t(8 * a + b)] +=
                      0.125 * gradient[a][i] * gradient[b][j];
        }
    return T;
  }();
  return tables;
}

std::vector<Eigen::Vector3d> cell_normals(const Octree& octree,
                                          const std::vector<ClippedTriangle>& pieces,
                                          const std::vector<int>& piece_cells) {
  if (piece_cells.size() != pieces.size())
    throw std::invalid_argument("cell_normals: one finest cell per piece expected");
  std::vector<Eigen::Vector3d> n(octree.finest().cells.size(), Eigen::Vector3d::Zero());
  // Serial in piece order: the sums, hence the normals, do not depend on the thread count.
  for (std::size_t p = 0; p < pieces.size(); ++p)
    n[std::size_t(piece_cells[p])] += pieces[p].cross();
  for (auto& v : n) {
    const double norm = v.norm();
    v = norm > 0.0 ? Eigen::Vector3d(v / norm) : Eigen::Vector3d::Zero();
  }
  return n;
}

namespace {
/// A cell's block h Σ_ij n_i n_j T_ij in the shape OctreeSystem::add_cell_blocks reads.
struct NormalGradientBlock {
  double s[64];
  double mass(int a, int b) const { return s[8 * a + b]; }
  double stiffness(int, int) const { return 0.0; }
};
}  // namespace

std::vector<double> assemble_normal_gradient(const OctreeSystem& system, const Octree& octree,
                                             const std::vector<Eigen::Vector3d>& normals) {
  if (system.level() != octree.num_levels() - 1)
    throw std::invalid_argument("assemble_normal_gradient: the finest level's system expected");
  if (normals.size() != octree.finest().cells.size())
    throw std::invalid_argument("assemble_normal_gradient: one normal per finest cell expected");
  const auto& T = unit_gradient_tables();
  const double h = octree.cube.cell_size();
  std::vector<double> values(std::size_t(system.non_zeros()), 0.0);
  system.for_each_tile([&](const int* cells, int count) {
    NormalGradientBlock block;
    for (int k = 0; k < count; ++k) {
      const int c = cells[k];
      const Eigen::Vector3d& n = normals[std::size_t(c)];
      for (int e = 0; e < 64; ++e) {
        double sum = 0.0;
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            sum += n[i] * n[j] * T[std::size_t(3 * i + j)][std::size_t(e)];
        block.s[e] = h * sum;
      }
      system.add_cell_blocks(c, block, values.data(), nullptr);
    }
    return 0LL;
  });
  return values;
}

}  // namespace mcf
