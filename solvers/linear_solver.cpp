#include "solvers/linear_solver.h"

#include <atomic>

namespace mcf {

const char* to_string(SolveStatus s) {
  switch (s) {
    case SolveStatus::converged: return "converged";
    case SolveStatus::max_iterations: return "max_iterations";
    case SolveStatus::not_positive_definite: return "not_positive_definite";
    case SolveStatus::numerical_issue: return "numerical_issue";
    case SolveStatus::failed: return "failed";
  }
  return "unknown";
}

std::uint64_t new_pattern_key() {
  static std::atomic<std::uint64_t> next{1};
  return next.fetch_add(1, std::memory_order_relaxed);
}

}  // namespace mcf
