#include "core/sparse.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace mcf {

double diagonal_sum(const SparseRef& A) {
  double sum = 0.0;
  const int* inner = A.innerIndexPtr();
  for (Eigen::Index j = 0; j < A.outerSize(); ++j) {
    const int* begin = inner + A.outerIndexPtr()[j];
    const int* end = inner + A.outerIndexPtr()[j + 1];
    const int* at = std::lower_bound(begin, end, int(j));
    if (at != end && *at == j) sum += A.valuePtr()[at - inner];
  }
  return sum;
}

SparseView view_of(const SparseMatrix& A) {
  if (!A.isCompressed()) throw std::invalid_argument("view_of: the matrix is not compressed");
  return SparseView(A.rows(), A.cols(), A.nonZeros(), A.outerIndexPtr(), A.innerIndexPtr(),
                    A.valuePtr());
}

SparseView view_of(const std::vector<int>& outer, const std::vector<int>& inner,
                   const std::vector<double>& values) {
  // One column start of 0 for the empty pattern: a map needs an outer array even with no columns.
  static const int kEmptyOuter[1] = {0};
  if (outer.empty()) return SparseView(0, 0, 0, kEmptyOuter, nullptr, nullptr);
  const auto n = static_cast<Eigen::Index>(outer.size()) - 1;
  if (inner.size() != values.size() || static_cast<std::size_t>(outer.back()) != inner.size())
    throw std::invalid_argument("view_of: " + std::to_string(values.size()) + " values and " +
                                std::to_string(inner.size()) + " row indices for a pattern of " +
                                std::to_string(outer.back()) + " nonzeros");
  return SparseView(n, n, static_cast<Eigen::Index>(inner.size()), outer.data(), inner.data(),
                    values.data());
}

}  // namespace mcf
