// The pattern helpers beside the solver interface (solvers/linear_solver.h): same_pattern, which
// decides whether a solver or ReducedSystem may refresh values only, and new_pattern_key.

#include "solvers/linear_solver.h"

#include <gtest/gtest.h>

#include <set>
#include <vector>

namespace {

using mcf::SparseMatrix;

SparseMatrix from_triplets(int n, const std::vector<Eigen::Triplet<double, int>>& t) {
  SparseMatrix A(n, n);
  A.setFromTriplets(t.begin(), t.end());
  A.makeCompressed();
  return A;
}

TEST(SamePattern, ComparesIndicesNotValues) {
  const SparseMatrix A = from_triplets(3, {{0, 0, 1.0}, {1, 0, 2.0}, {0, 1, 2.0}, {1, 1, 3.0}, {2, 2, 4.0}});
  const SparseMatrix B = from_triplets(3, {{0, 0, -7.0}, {1, 0, 0.5}, {0, 1, 0.5}, {1, 1, 9.0}, {2, 2, 1.0}});
  EXPECT_TRUE(mcf::same_pattern(A, B));
  EXPECT_TRUE(mcf::same_pattern(A, A));
  // Same count of entries, one row index moved: (1, 0) -> (2, 0) and (0, 1) -> (0, 2).
  const SparseMatrix C = from_triplets(3, {{0, 0, 1.0}, {2, 0, 2.0}, {0, 2, 2.0}, {1, 1, 3.0}, {2, 2, 4.0}});
  EXPECT_FALSE(mcf::same_pattern(A, C));
  // One entry fewer; a different size.
  EXPECT_FALSE(mcf::same_pattern(A, from_triplets(3, {{0, 0, 1.0}, {1, 1, 3.0}, {2, 2, 4.0}})));
  EXPECT_FALSE(mcf::same_pattern(A, from_triplets(4, {{0, 0, 1.0}, {1, 0, 2.0}, {0, 1, 2.0}, {1, 1, 3.0}, {2, 2, 4.0}})));
  // Not compressed: never the same (its stored arrays are not a plain CSC pattern).
  SparseMatrix U = A;
  U.insert(2, 1) = 1.0;  // leaves U uncompressed
  ASSERT_FALSE(U.isCompressed());
  EXPECT_FALSE(mcf::same_pattern(A, U));
  EXPECT_FALSE(mcf::same_pattern(U, U));
}

TEST(PatternKey, NeverZeroNeverRepeated) {
  std::set<std::uint64_t> seen;
  for (int i = 0; i < 1000; ++i) {
    const std::uint64_t k = mcf::new_pattern_key();
    EXPECT_NE(k, 0u);
    EXPECT_TRUE(seen.insert(k).second) << "key " << k << " repeated";
  }
}

}  // namespace
