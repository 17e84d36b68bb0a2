#include "datasets/face_order.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <vector>

namespace mcf {
namespace {

TEST(FaceOrder, SortsBySmallestVertexAndKeepsTiesInOrder) {
  Triangles F(5, 3);
  F << 4, 2, 3,  //
      0, 5, 1,   //
      3, 4, 2,   //
      6, 1, 5,   //
      2, 6, 7;
  const Triangles out = faces_by_smallest_vertex(F, 8);
  Triangles expected(5, 3);
  expected << 0, 5, 1,  //
      6, 1, 5,          //
      4, 2, 3,          // smallest vertex 2, first of its three in F
      3, 4, 2,          //
      2, 6, 7;
  EXPECT_EQ(out, expected);
}

TEST(FaceOrder, IsAPermutationOfTheRows) {
  // A larger case: every row of F appears in the output as often as in F, corners in place.
  Triangles F(200, 3);
  for (int f = 0; f < 200; ++f) F.row(f) << (7 * f) % 101, (13 * f + 5) % 101, (29 * f + 11) % 101;
  const Triangles out = faces_by_smallest_vertex(F, 101);
  ASSERT_EQ(out.rows(), F.rows());
  const auto rows = [](const Triangles& T) {
    std::vector<std::array<int, 3>> r;
    for (Eigen::Index f = 0; f < T.rows(); ++f) r.push_back({T(f, 0), T(f, 1), T(f, 2)});
    return r;
  };
  auto a = rows(F), b = rows(out);
  for (Eigen::Index f = 1; f < out.rows(); ++f)
    EXPECT_LE(out.row(f - 1).minCoeff(), out.row(f).minCoeff());
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  EXPECT_EQ(a, b);
}

}  // namespace
}  // namespace mcf
