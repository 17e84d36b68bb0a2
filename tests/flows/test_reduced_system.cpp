// ReducedSystem (flows/reduced_system.cpp) hands the solver a pattern key for the tracked basis's
// fixed pattern: the multigrid solver then compares the pattern never, builds the Galerkin
// pattern once, and solves exactly as a solver that compares (here: a fresh one every step).
// With no function held it hands over M and K, not their sum (LinearSolver::set_matrix_sum).

#include "flows/reduced_system.h"

#include "bases/tracked_octree_basis.h"
#include "datasets/generators.h"
#include "solvers/multigrid.h"

#include <gtest/gtest.h>

namespace mcf {
namespace {

TEST(ReducedSystem, TrackedPatternIsVouchedForAndSolvesAsAComparingSolver) {
  OctreeOptions o;
  o.depth = 5;
  o.cube = OctreeCube::tight;
  TrackedOctreeBasis basis(make_icosphere(3), o);
  MultigridSolver kept;
  ReducedSystem system(basis, kept);
  const double dt = 1e-3;
  Coefficients x = basis.initial_coefficients();
  for (int step = 0; step < 3; ++step) {
    basis.update(x, true, true);
    const Coefficients R = basis.mass() * x;
    const Coefficients y = system.solve(1.0, dt, R, x, x);
    ASSERT_TRUE(system.report().ok()) << system.report().message;

    MultigridSolver fresh;  // new solver and system: builds and checks everything itself
    ReducedSystem reference(basis, fresh);
    const Coefficients y_ref = reference.solve(1.0, dt, R, x, x);
    ASSERT_TRUE(reference.report().ok());
    EXPECT_LT((y - y_ref).norm(), 1e-12 * y_ref.norm()) << "step " << step;
    EXPECT_GT((y - x).norm(), 1e-6 * x.norm()) << "the flow moved";
    x = y;
  }
  EXPECT_EQ(kept.symbolic_builds(), 1);
  EXPECT_EQ(kept.numeric_builds(), 3);
  EXPECT_EQ(kept.pattern_comparisons(), 0);  // 2 without the key
}

// With no function held, ReducedSystem hands the solver M and K (set_matrix_sum) instead of
// forming M + dt K itself; the solution must be bitwise the one of set_matrix on the sum formed
// by hand, for the semi-implicit system and for the mass alone (b = 0, explicit steps).
TEST(ReducedSystem, HandsTheSumToTheSolverBitwiseAsItsOwnSum) {
  OctreeOptions o;
  o.depth = 5;
  o.cube = OctreeCube::tight;
  TrackedOctreeBasis basis(make_icosphere(3), o);
  const Coefficients x = basis.initial_coefficients();
  basis.update(x, true, true);
  const Coefficients R = basis.mass() * x;
  for (const double b : {1e-3, 0.0}) {
    SCOPED_TRACE(b);
    MultigridSolver handed, by_hand;
    ReducedSystem system(basis, handed);
    const Coefficients y = system.solve(1.0, b, R, x, x);
    ASSERT_TRUE(system.report().ok()) << system.report().message;
    ASSERT_EQ(system.num_fixed(), 0u) << "a closed sphere holds no function: the sum is handed over";

    SparseMatrix S = basis.mass();
    sum_on_pattern(1.0, basis.mass(), b, basis.stiffness(), S);
    ASSERT_TRUE(by_hand.set_matrix(S, {basis.prolongations(), basis.colours()}).ok());
    Eigen::MatrixXd y_ref = x;
    ASSERT_TRUE(by_hand.solve(R, y_ref).ok());
    EXPECT_EQ((y - y_ref).cwiseAbs().maxCoeff(), 0.0);
    // With b = 0 the system is M y = M x, so the warm start x is the answer up to the rounding of
    // its residual, amplified by M's conditioning (measured 3.8e-8 relative). With b = 1e-3 the
    // coefficients move by O(‖x‖) (0.69 ‖x‖ for a direct solve, measured: at this coarse depth the
    // functions that barely touch the surface are smoothed hard, while the vertices move ~2δ).
    if (b != 0) EXPECT_GT((y - x).norm(), 0.1 * x.norm());
    else EXPECT_LT((y - x).norm(), 1e-6 * x.norm());
  }
}

}  // namespace
}  // namespace mcf
