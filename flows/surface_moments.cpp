#include "flows/surface_moments.h"

#include "core/parallel.h"

#include <vector>

namespace mcf {

SurfaceMoments surface_moments(const Positions& V, const Triangles& F) {
  constexpr Eigen::Index kChunk = 8192;  // faces per partial sum: fixed, never the thread count
  const Eigen::Index m = F.rows();
  std::vector<SurfaceMoments> partial(std::size_t((m + kChunk - 1) / kChunk));
  parallel_for_chunks<Eigen::Index>(
      m, kChunk, [&](Eigen::Index c, Eigen::Index f0, Eigen::Index f1) {
        SurfaceMoments s;
        for (Eigen::Index f = f0; f < f1; ++f) {
          const Eigen::RowVector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), d = V.row(F(f, 2));
          const double A = 0.5 * (b - a).cross(d - a).norm();
          s.area += A;
          s.weighted_centroid += A * (a + b + d) / 3.0;
        }
        partial[std::size_t(c)] = s;
      });
  SurfaceMoments total;
  for (const SurfaceMoments& s : partial) {
    total.area += s.area;
    total.weighted_centroid += s.weighted_centroid;
  }
  return total;
}

}  // namespace mcf
