#pragma once
// Monotone decrease of an iterative solver's relative residuals, checked only above the rounding
// floor. Below about 1e4 machine epsilons a relative residual ||b - Ax|| / ||b|| is rounding
// noise (the residual's own evaluation errs by ~nnz-per-row * eps * ||A|| ||x|| / ||b||), and its
// last digits differ between processors and vector widths: a cycle there may "raise" it.

#include <gtest/gtest.h>

#include <cstddef>
#include <limits>
#include <sstream>

namespace mcf::testing {

inline constexpr double kRelativeResidualFloor = 1e4 * std::numeric_limits<double>::epsilon();

/// Success when every residual r[i] with r[i-1] above `floor` is below r[i-1]. `residuals` is
/// any indexable sequence whose elements convert to double (a std::vector, a JSON array).
template <class Sequence>
::testing::AssertionResult falls_above_rounding_floor(const Sequence& residuals,
                                                      double floor = kRelativeResidualFloor) {
  for (std::size_t i = 1; i < residuals.size(); ++i) {
    const double before = residuals[i - 1], after = residuals[i];
    if (before <= floor) break;
    if (!(after < before)) {
      std::ostringstream s;
      s << "residual rises at iteration " << i << ": " << before << " -> " << after << " (floor "
        << floor << ")";
      return ::testing::AssertionFailure() << s.str();
    }
  }
  return ::testing::AssertionSuccess();
}

}  // namespace mcf::testing
