// The pattern helpers beside the solver interface (solvers/linear_solver.h): same_pattern, which
// decides whether a solver or ReducedSystem may refresh values only, sum_on_pattern,
// new_pattern_key, and the default LinearSolver::set_matrix_sum.

#include "solvers/linear_solver.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <string>
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
  const SparseMatrix A =
      from_triplets(3, {{0, 0, 1.0}, {1, 0, 2.0}, {0, 1, 2.0}, {1, 1, 3.0}, {2, 2, 4.0}});
  const SparseMatrix B =
      from_triplets(3, {{0, 0, -7.0}, {1, 0, 0.5}, {0, 1, 0.5}, {1, 1, 9.0}, {2, 2, 1.0}});
  EXPECT_TRUE(mcf::same_pattern(A, B));
  EXPECT_TRUE(mcf::same_pattern(A, A));
  // Same count of entries, one row index moved: (1, 0) -> (2, 0) and (0, 1) -> (0, 2).
  const SparseMatrix C =
      from_triplets(3, {{0, 0, 1.0}, {2, 0, 2.0}, {0, 2, 2.0}, {1, 1, 3.0}, {2, 2, 4.0}});
  EXPECT_FALSE(mcf::same_pattern(A, C));
  // One entry fewer; a different size.
  EXPECT_FALSE(mcf::same_pattern(A, from_triplets(3, {{0, 0, 1.0}, {1, 1, 3.0}, {2, 2, 4.0}})));
  EXPECT_FALSE(mcf::same_pattern(
      A, from_triplets(4, {{0, 0, 1.0}, {1, 0, 2.0}, {0, 1, 2.0}, {1, 1, 3.0}, {2, 2, 4.0}})));
  // Not compressed: never the same (its stored arrays are not a plain CSC pattern).
  SparseMatrix U = A;
  U.insert(2, 1) = 1.0;  // leaves U uncompressed
  ASSERT_FALSE(U.isCompressed());
  EXPECT_FALSE(mcf::same_pattern(A, U));
  EXPECT_FALSE(mcf::same_pattern(U, U));
  // Maps of one pattern's arrays (a basis's mass and stiffness views) with their own values.
  const std::vector<double> values(std::size_t(A.nonZeros()), 5.0);
  const Eigen::Map<const SparseMatrix> V(3, 3, A.nonZeros(), A.outerIndexPtr(), A.innerIndexPtr(),
                                         values.data());
  EXPECT_TRUE(mcf::same_pattern(V, A));
  EXPECT_TRUE(mcf::same_pattern(V, B));
  EXPECT_FALSE(mcf::same_pattern(V, C));
  // The same arrays seen with fewer entries or columns are another pattern.
  const Eigen::Map<const SparseMatrix> W(2, 2, 4, A.outerIndexPtr(), A.innerIndexPtr(),
                                         values.data());
  EXPECT_FALSE(mcf::same_pattern(V, W));
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

/// Keeps a copy of what set_matrix was given, so the default set_matrix_sum can be checked
/// against sum_on_pattern without any solver's own arithmetic in between.
class RecordingSolver : public mcf::LinearSolver {
 public:
  std::string name() const override { return "recording"; }
  mcf::SolveReport set_matrix(const SparseMatrix& A, mcf::HierarchyView h = {}) override {
    given = A;
    key = h.pattern_key;
    ++calls;
    return {};
  }
  mcf::SolveReport solve_in_place(const mcf::ConstMatrixRef&, mcf::MatrixRef) override {
    return {};
  }
  SparseMatrix given;
  std::uint64_t key = 0;
  int calls = 0;
};

bool bitwise_equal(const SparseMatrix& A, const SparseMatrix& B) {
  return mcf::same_pattern(A, B) &&
         std::equal(A.valuePtr(), A.valuePtr() + A.nonZeros(), B.valuePtr());
}

// The default hands set_matrix exactly sum_on_pattern's matrix; it follows a change of pattern
// (same count of entries, so only the comparison can see it) when no key vouches for it, and
// operands off one pattern get Eigen's general sum (the union of the patterns), without a key.
TEST(SetMatrixSum, DefaultHandsOverSumOnPattern) {
  using T = Eigen::Triplet<double, int>;
  const SparseMatrix M1 =
      from_triplets(3, {T{0, 0, 2.0}, T{1, 0, 0.5}, T{0, 1, 0.5}, T{1, 1, 3.0}, T{2, 2, 4.0}});
  const SparseMatrix K1 =
      from_triplets(3, {T{0, 0, 1.0}, T{1, 0, -1.0}, T{0, 1, -1.0}, T{1, 1, 1.0}, T{2, 2, 0.0}});
  const SparseMatrix M2 =
      from_triplets(3, {T{0, 0, 2.0}, T{2, 0, 0.25}, T{0, 2, 0.25}, T{1, 1, 3.0}, T{2, 2, 4.0}});
  const SparseMatrix K2 =
      from_triplets(3, {T{0, 0, 1.0}, T{2, 0, -1.0}, T{0, 2, -1.0}, T{1, 1, 7.0}, T{2, 2, 1.0}});
  ASSERT_FALSE(mcf::same_pattern(M1, M2));
  auto sum = [](double a, const SparseMatrix& M, double b, const SparseMatrix& K) {
    SparseMatrix S = M;
    mcf::sum_on_pattern(a, M, b, K, S);
    return S;
  };
  RecordingSolver s;
  const std::uint64_t key = mcf::new_pattern_key();
  ASSERT_TRUE(s.set_matrix_sum(1.0, M1, 0.1, K1, {nullptr, nullptr, key}).ok());
  EXPECT_TRUE(bitwise_equal(s.given, sum(1.0, M1, 0.1, K1)));
  EXPECT_EQ(s.key, key);
  ASSERT_TRUE(
      s.set_matrix_sum(2.0, M1, 0.3, K1, {nullptr, nullptr, key}).ok());  // vouched: values only
  EXPECT_TRUE(bitwise_equal(s.given, sum(2.0, M1, 0.3, K1)));
  ASSERT_TRUE(s.set_matrix_sum(1.0, M2, 0.1, K2).ok());  // no key: compared, new pattern taken
  EXPECT_TRUE(bitwise_equal(s.given, sum(1.0, M2, 0.1, K2)));
  const double expected = 1.0 * 0.25 + 0.1 * -1.0;
  EXPECT_EQ(s.given.coeff(2, 0), expected);
  EXPECT_EQ(s.calls, 3);

  const SparseMatrix K3 = from_triplets(3, {T{2, 2, 1.0}, T{2, 1, 5.0}, T{1, 2, 5.0}});
  ASSERT_FALSE(mcf::summable(M1, K3));
  ASSERT_TRUE(s.set_matrix_sum(1.0, M1, 0.1, K3, {nullptr, nullptr, key}).ok());
  EXPECT_EQ(s.calls, 4);
  EXPECT_EQ(s.key, 0u) << "the union pattern is not what the key vouched for";
  const SparseMatrix general = 1.0 * M1 + 0.1 * K3;
  EXPECT_EQ(s.given.nonZeros(), 7);
  EXPECT_LT((s.given - general).norm(), 1e-15 * general.norm());
  EXPECT_EQ(s.given.coeff(2, 1), 0.5);
  EXPECT_EQ(s.given.coeff(1, 0), 0.5);
}

}  // namespace
