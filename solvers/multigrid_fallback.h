#pragma once
// A multigrid solve that does not return a silently inexact answer. A fixed number k of cycles a
// step (the fast setting) is guarded twice after its cycles:
//
// - Where the step ends: a step is `converged` only at or below `residual_bound`, a relative
//   residual ||b - A x|| / ||b||. Contracting cycles can still end far from the solution when the
//   step starts far from it (the integrator's prediction misses near a fold, or one cycle from a
//   poor start), so a step that ends above the bound continues: a few cheap V(2,2)-cycles with
//   the bound as their tolerance, where the measured contraction predicts that they reach it;
//   otherwise CG preconditioned by the configured cycle to the bound; then the factorization
//   (below).
// - How fast the cycles contract: k cycles promise to reduce the step's initial residual r_0 by
//   at least stall_ratio^k. When they stall — their mean reduction per cycle is worse, as on the
//   paper's octree system or a surface whose triangles degenerate during the flow — the solve goes
//   on with CG preconditioned by the same cycle, from the cycles' iterate, until the residual is
//   what healthy cycles would have reached, r_0 · stall_ratio^k, or the bound if that is lower
//   (never below `tolerance`). Krylov acceleration removes the few slow modes (error-propagation
//   eigenvalues near 1) that stall a cycle in a few iterations, so the step is as accurate as a
//   step of contracting cycles at a few more cycles' cost. Solving to a fixed small tolerance
//   instead can cost a thousand iterations on a nearly degenerate mesh, for no accuracy the flow
//   can see.
//
// CG is not the last resort. Where the surface degenerates, the cycle loses its grip on more and
// more modes and CG by the cycle needs tens, then hundreds of iterations; near a fold, with
// cotangent weights many orders above the mass, p^T A p can even round to a non-positive number
// although the matrix is positive definite, and CG breaks down. So CG gets `direct_after`
// iterations: when it has not reached its target by then, or breaks down earlier, the step is
// solved by a sparse Cholesky factorization (CHOLMOD) of the same matrix, and every later step of
// this solver that needs more than its cycles goes to the factorization straight after them (a
// flow that degenerates does not recover). The factorization's symbolic analysis is kept while the
// pattern stays. Where the matrix is not positive definite to working precision either, the
// factorization says so, and the step fails as a CHOLMOD flow's would.
//
// - Smooth steps: where the caller says the step's start fit its prediction
//   (LinearSolver::set_start_fit, θ >= kSmoothStartFit: the motion continues as extrapolated)
//   and the cycles contracted, the flow is in a smooth stretch: an error the cycles leave there
//   is damped by the following steps, as the flow's diffusion damps any perturbation, where near
//   a fold the operators change with the positions and a step's error grows. Such a step keeps
//   its fixed work even above the bound and says so (`max_iterations`, with the residual and θ
//   in the message), unless `bound_smooth_steps`. The first step (no prediction) and every step
//   without a start fit are held to the bound.
//
// The guard costs nothing on a step whose cycles contract and end under the bound but one
// residual pass (to know the contraction); CG and the factorization read the finest matrix in the
// caller's numbering, which the multigrid lays out at the first step that needs them and
// refreshes in place after (finest_matrix()).
//
// Status: `converged` where the step ended at or below the bound (or, with no bound, where CG
// reached its stall target), or the factorization solved it; `max_iterations` where the cycles
// were not checked against a bound (residual_bound 0), a smooth step kept its fixed work above
// it, or CG ran out with no factorization allowed.

#include "solvers/cholmod_solver.h"
#include "solvers/multigrid.h"
#include "solvers/pcg_solver.h"

#include <memory>

namespace mcf {

/// The relative residual at or below which a fixed-work step counts as converged, unless the
/// configuration sets another (solver.residual_bound; docs/flow.md "Guarded cycles" gives the
/// measurements behind it).
inline constexpr double kDefaultResidualBound = 1e-4;

/// The start fit θ (LinearSolver::set_start_fit) from which a step counts as smooth. On the
/// measured flows (docs/flow.md "Guarded cycles") steps approaching a fold fit at θ <= 0.06 (the
/// extrapolation overshoots an accelerating motion) and steps of smooth stretches, scanned
/// models' included, at θ >= 0.6 after the first two.
inline constexpr double kSmoothStartFit = 0.5;

/// Gauss-Seidel sweeps each way of the V-cycles that continue a contracting step that ended
/// above the bound (fewer where the configured cycle has fewer).
inline constexpr int kExtraCycleSweeps = 2;

struct StallFallbackOptions {
  /// Fall back when the cycles' mean contraction (SolveReport::contraction) exceeds this; CG then
  /// stops at r_0 · stall_ratio^k (or at residual_bound, if lower). 0 = no stall test.
  double stall_ratio = 0.2;
  /// A step ending above this relative residual continues (more cycles, CG, the factorization)
  /// until it is at or below it; 0 = no bound (the stall test alone).
  double residual_bound = kDefaultResidualBound;
  /// Hold smooth steps to the bound too. By default a step whose start fit the caller's
  /// prediction (start_fit() >= kSmoothStartFit) and whose cycles did not stall keeps its fixed
  /// work above the bound, with status max_iterations and a note.
  bool bound_smooth_steps = false;
  double tolerance = 1e-10;  ///< the fallback CG never stops below this relative residual
  int max_iterations = 1000;
  /// CG iterations after which a stalled step goes to the factorization (also at once on a
  /// breakdown); 0 = never (CG runs to max_iterations and a breakdown fails the step).
  int direct_after = 10;
  int direct_blas_threads = kKeepBlasThreads;  ///< the factorization's OpenBLAS threads
};

class FallbackMultigridSolver final : public LinearSolver {
 public:
  FallbackMultigridSolver(MultigridOptions cycles, StallFallbackOptions fallback);
  std::string name() const override { return multigrid_.name() + "+fallback"; }
  SolveReport set_matrix(const SparseMatrix& A, HierarchyView hierarchy = {}) override;
  SolveReport set_matrix_sum(const MatrixSum& sum, HierarchyView hierarchy = {}) override;
  using LinearSolver::set_matrix_sum;
  /// Solves that needed more than their cycles (extra cycles, CG or the factorization) since
  /// construction.
  int fallbacks() const { return fallbacks_; }
  /// Solves that the factorization finished since construction.
  int direct_solves() const { return direct_solves_; }

 protected:
  /// The cycles; then, if they ended above the bound while contracting, up to max(2, k) more
  /// V-cycles of at most kExtraCycleSweeps sweeps each way when the contraction predicts they
  /// reach it (stopping at a cycle that does not halve the residual); then, if the step is still
  /// above the bound or the cycles stalled, CG; then,
  /// if CG broke down, did not reach its target in `direct_after` iterations or is on course not
  /// to (PcgOptions::give_up_off_course), the factorization. The report lists the residuals of the
  /// cycles, the extra cycles and CG in order (the factorization's last), `iterations` counts all
  /// of them, `extra_cycles` the added cycles, `fallback_iterations` CG's, and `direct_fallback`
  /// says whether the factorization gave the answer; the message says what ran and why.
  SolveReport solve_in_place(const ConstMatrixRef& B, MatrixRef X) override;

 private:
  MultigridSolver multigrid_;
  StallFallbackOptions fallback_;
  std::unique_ptr<PcgSolver> pcg_;
  bool pcg_current_ = false;  ///< pcg_ holds the multigrid's present finest matrix
  std::unique_ptr<CholmodSolver> direct_;
  bool direct_current_ = false;  ///< direct_ holds the factor of the present finest matrix
  /// A step went to the factorization: later ones that need more than their cycles go at once.
  bool prefer_direct_ = false;
  int fallbacks_ = 0;
  int direct_solves_ = 0;

  /// Solves B by the factorization into X; `before` is what ran first (cycles, CG).
  SolveReport solve_direct(const ConstMatrixRef& B, MatrixRef X, SolveReport before,
                           const std::string& why);
};

}  // namespace mcf
