// ReducedSystem (flows/reduced_system.cpp) hands the solver a pattern key for the tracked basis's
// fixed pattern: the multigrid solver then compares the pattern never, builds the Galerkin
// pattern once, and solves exactly as a solver that compares (here: a fresh one every step).

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

}  // namespace
}  // namespace mcf
