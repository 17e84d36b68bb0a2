#include "solvers/linear_solver.h"

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

}  // namespace mcf
