// The sparse-matrix vocabulary of core/sparse.h.

#include "core/sparse.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

namespace mcf {
namespace {

// view_of describes compressed storage only, and a pattern whose values match it.
TEST(Sparse, ViewOfRefusesWhatItCannotDescribe) {
  SparseMatrix U(3, 3);
  U.insert(0, 0) = 1.0;  // leaves U uncompressed
  EXPECT_THROW((void)view_of(U), std::invalid_argument);
  U.makeCompressed();
  EXPECT_EQ(view_of(U).coeff(0, 0), 1.0);
  const std::vector<int> outer{0, 1, 2}, inner{0, 1};
  EXPECT_THROW((void)view_of(outer, inner, std::vector<double>{1.0}), std::invalid_argument);
  const std::vector<double> values{2.0, 3.0};
  const SparseView V = view_of(outer, inner, values);
  EXPECT_EQ(V.rows(), 2);
  EXPECT_EQ(V.coeff(1, 1), 3.0);
  EXPECT_EQ(view_of(std::vector<int>{}, std::vector<int>{}, std::vector<double>{}).rows(), 0);
}

}  // namespace
}  // namespace mcf
