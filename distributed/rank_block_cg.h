#pragma once
// Conjugate gradients on the three coordinates at once across ranks, preconditioned by one cycle
// of the surface multigrid (distributed/rank_multigrid.h): each column has its own step lengths
// and stops on its own, but every product with the matrix and every cycle serves the three (one
// pass over each matrix entry, one message per exchange). The cycle is symmetric (forward sweeps
// down, backward up), so the preconditioner is symmetric positive definite as CG needs.
//
// A column stops when its residual, as CG updates it, is at most `tolerance` ||b||; the dot
// products are summed in rank order (distributed/comm.h), so a rerun on the same ranks gives the
// same bits. Blocks as in rank_multigrid.h (n x 4, row-major, column 3 zero). Collective.

#include "distributed/rank_multigrid.h"

#include <array>

namespace mcf::dist {

struct BlockCgReport {
  std::array<int, 3> iterations{0, 0, 0};
  std::array<bool, 3> converged{false, false, false};
  /// A column whose search direction had pᵀAp <= 0 (the matrix or the cycle is not positive
  /// definite): it stopped there.
  std::array<bool, 3> breakdown{false, false, false};
};

/// Improves X in place for the columns marked `active`; the others are left as they are.
BlockCgReport block_cg(RankMultigrid& multigrid, const double* B, double* X,
                       std::array<bool, 3> active, double tolerance, int max_iterations);

/// Per column ||B - A X|| / ||B|| (||B - A X|| where ||B|| = 0), summed in rank order.
std::array<double, 3> relative_residuals(RankMultigrid& multigrid, const double* B,
                                         const double* X);

}  // namespace mcf::dist
