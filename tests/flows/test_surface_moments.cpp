// The surface's area and area-weighted centroid against a serial face-by-face sum and against
// datasets' surface_area; the same bits on one thread as on two.

#include "flows/surface_moments.h"

#include "datasets/generators.h"
#include "datasets/validate.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

namespace mcf {
namespace {

TEST(SurfaceMoments, MatchTheSerialSumOnAnOffCentreSphere) {
  TriangleMesh m = make_icosphere(6);  // 81920 faces: ten chunks of partial sums
  m.vertices.rowwise() += Eigen::RowVector3d(0.3, -0.2, 0.7);
  m.vertices.col(0) *= 1.5;  // an ellipsoid: the faces' areas differ
  double area = 0;
  Eigen::RowVector3d weighted = Eigen::RowVector3d::Zero();
  for (Eigen::Index f = 0; f < m.faces.rows(); ++f) {
    const Eigen::RowVector3d a = m.vertices.row(m.faces(f, 0)), b = m.vertices.row(m.faces(f, 1)),
                             c = m.vertices.row(m.faces(f, 2));
    const double A = 0.5 * (b - a).cross(c - a).norm();
    area += A;
    weighted += A * (a + b + c) / 3.0;
  }
  const SurfaceMoments s = surface_moments(m.vertices, m.faces);
  EXPECT_NEAR(s.area, area, 1e-12 * area);
  EXPECT_NEAR(s.area, surface_area(m), 1e-12 * area);
  EXPECT_LT((s.weighted_centroid - weighted).norm(), 1e-12 * weighted.norm());
  // The centroid of the symmetric ellipsoid is its centre.
  EXPECT_LT((s.weighted_centroid / s.area - Eigen::RowVector3d(0.3 * 1.5, -0.2, 0.7)).norm(), 1e-9);
}

TEST(SurfaceMoments, OneAndTwoThreadsGiveTheSameBits) {
  const TriangleMesh m = make_icosphere(6);
  auto moments = [&](int threads) {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, threads);
    return surface_moments(m.vertices, m.faces);
  };
  const SurfaceMoments one = moments(1), two = moments(2);
  EXPECT_EQ(one.area, two.area);
  EXPECT_EQ(one.weighted_centroid, two.weighted_centroid);
}

}  // namespace
}  // namespace mcf
