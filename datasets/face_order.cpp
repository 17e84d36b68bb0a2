#include "datasets/face_order.h"

#include <vector>

namespace mcf {

Triangles faces_by_smallest_vertex(const Triangles& F, Eigen::Index vertices) {
  std::vector<Eigen::Index> start(std::size_t(vertices) + 1, 0);
  const auto first = [&](Eigen::Index f) { return std::size_t(F.row(f).minCoeff()); };
  for (Eigen::Index f = 0; f < F.rows(); ++f) ++start[first(f) + 1];
  for (std::size_t v = 1; v < start.size(); ++v) start[v] += start[v - 1];
  Triangles out(F.rows(), 3);
  for (Eigen::Index f = 0; f < F.rows(); ++f) out.row(start[first(f)]++) = F.row(f);
  return out;
}

}  // namespace mcf
