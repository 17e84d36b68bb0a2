#include "flows/surface_moments.h"

#include "core/parallel.h"

namespace mcf {

SurfaceMoments surface_moments(const Positions& V, const Triangles& F) {
  constexpr Eigen::Index kChunk = 8192;  // faces per partial sum: fixed, never the thread count
  return sum_over_chunks<SurfaceMoments>(F.rows(), kChunk, [&](Eigen::Index f0, Eigen::Index f1) {
    SurfaceMoments s;
    for (Eigen::Index f = f0; f < f1; ++f) {
      const Eigen::RowVector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), d = V.row(F(f, 2));
      const double A = 0.5 * (b - a).cross(d - a).norm();
      s.area += A;
      s.weighted_centroid += A * (a + b + d) / 3.0;
    }
    return s;
  });
}

}  // namespace mcf
