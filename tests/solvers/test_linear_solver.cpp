// The pattern helpers beside the solver interface (solvers/linear_solver.h): same_pattern, which
// decides whether a solver or ReducedSystem may refresh values only, sum_on_pattern, and
// new_pattern_key.

#include "solvers/linear_solver.h"

#include <gtest/gtest.h>

#include <set>
#include <utility>
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

// sum_on_pattern against Eigen's general sparse sum (which merges patterns itself), on a matrix
// large enough to be split across threads; S's pattern is left as it was.
TEST(SumOnPattern, EqualsEigensSum) {
  const int n = 40000;
  std::vector<Eigen::Triplet<double, int>> tm, tk;
  for (int i = 0; i < n; ++i) {
    tm.emplace_back(i, i, 1.0 + 0.25 * (i % 7));
    tk.emplace_back(i, i, 2.0 - 0.5 * (i % 3));
    if (i + 1 < n) {
      for (const auto& [r, c] : {std::pair{i, i + 1}, std::pair{i + 1, i}}) {
        tm.emplace_back(r, c, 0.1 * (i % 5));
        tk.emplace_back(r, c, -0.3 - 0.01 * (i % 11));
      }
    }
  }
  const SparseMatrix M = from_triplets(n, tm), K = from_triplets(n, tk);
  ASSERT_TRUE(mcf::same_pattern(M, K));
  SparseMatrix S = M;
  mcf::sum_on_pattern(0.5, M, 1e-3, K, S);
  const SparseMatrix ref = 0.5 * M + 1e-3 * K;
  EXPECT_TRUE(mcf::same_pattern(S, M));
  EXPECT_LT((S - ref).norm(), 1e-15 * ref.norm());
  EXPECT_GT(ref.norm(), 0.0);
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
