// ReducedSystem (steps/reduced_system.cpp) hands the solver a pattern key for the tracked basis's
// fixed pattern: the multigrid solver then compares the pattern never, builds the Galerkin
// pattern once, and solves exactly as a solver that compares (here: a fresh one every step).
// With no function held it hands over M and K, not their sum (LinearSolver::set_matrix_sum).

#include "steps/reduced_system.h"

#include "bases/tracked_octree_basis.h"
#include "datasets/generators.h"
#include "solvers/cholmod_solver.h"
#include "solvers/multigrid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>

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
    ASSERT_EQ(system.num_fixed(), 0u)
        << "a closed sphere holds no function: the sum is handed over";

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
    if (b != 0)
      EXPECT_GT((y - x).norm(), 0.1 * x.norm());
    else
      EXPECT_LT((y - x).norm(), 1e-6 * x.norm());
  }
}

/// A chain of n = 2 nc - 1 hat functions on [0, 1] (1-D mass and stiffness, one pattern) with a
/// two-level hierarchy (linear interpolation from nc functions). `empty` rows and columns are
/// zeroed in M and K, as a pinch leaves the functions no cubature point reaches.
class ChainBasis : public Basis {
 public:
  ChainBasis(int nc, std::vector<int> locked) : locked_(std::move(locked)) {
    const int n = 2 * nc - 1;
    const double h = 1.0 / (n - 1);
    std::vector<Eigen::Triplet<double>> m, k, p;
    for (int i = 0; i < n; ++i)
      for (int j = std::max(0, i - 1); j <= std::min(n - 1, i + 1); ++j) {
        m.emplace_back(i, j, i == j ? 2 * h / 3 : h / 6);
        k.emplace_back(i, j, i == j ? 2 / h : -1 / h);
      }
    for (int J = 0; J < nc; ++J) {
      p.emplace_back(2 * J, J, 1.0);
      if (J > 0) p.emplace_back(2 * J - 1, J, 0.5);
      if (J + 1 < nc) p.emplace_back(2 * J + 1, J, 0.5);
    }
    full_mass_.resize(n, n);
    full_stiffness_.resize(n, n);
    full_mass_.setFromTriplets(m.begin(), m.end());
    full_stiffness_.setFromTriplets(k.begin(), k.end());
    SparseMatrix P(n, nc);
    P.setFromTriplets(p.begin(), p.end());
    P.makeCompressed();
    prolongations_ = {P};
    set_empty({});
  }
  /// M and K with these rows and columns zeroed (explicit zeros: the pattern stays).
  void set_empty(const std::set<int>& empty) {
    mass_ = full_mass_;
    stiffness_ = full_stiffness_;
    for (SparseMatrix* A : {&mass_, &stiffness_})
      for (int c = 0; c < A->outerSize(); ++c)
        for (SparseMatrix::InnerIterator it(*A, c); it; ++it)
          if (empty.count(c) || empty.count(int(it.row()))) it.valueRef() = 0.0;
  }
  std::string name() const override { return "chain"; }
  Eigen::Index dimension() const override { return full_mass_.rows(); }
  Coefficients initial_coefficients() const override {
    Coefficients x(dimension(), 3);
    for (Eigen::Index i = 0; i < x.rows(); ++i)
      x.row(i) << double(i), std::sin(double(i)), 1.0 + 0.1 * double(i * i);
    return x;
  }
  void update(const Coefficients&, bool, bool) override {}
  SparseView mass() const override { return view_of(mass_); }
  SparseView stiffness() const override { return view_of(stiffness_); }
  Positions evaluate_vertices(const Coefficients& x) const override { return x; }
  std::vector<int> locked_functions() const override { return locked_; }
  const std::vector<SparseMatrix>* prolongations() const override { return &prolongations_; }
  const BasisStats& stats() const override { return stats_; }

 private:
  std::vector<int> locked_;
  SparseMatrix full_mass_, full_stiffness_, mass_, stiffness_;
  std::vector<SparseMatrix> prolongations_;
  BasisStats stats_;
};

/// (a M + b K) Y = R with the `held` rows fixed at `v` and eliminated: dense, from the definition.
Coefficients eliminated_solution(const ChainBasis& basis, double a, double b, const Coefficients& R,
                                 const Coefficients& v, const std::set<int>& held) {
  const Eigen::MatrixXd S =
      a * Eigen::MatrixXd(basis.mass()) + b * Eigen::MatrixXd(basis.stiffness());
  std::vector<int> free;
  for (int i = 0; i < int(S.rows()); ++i)
    if (!held.count(i)) free.push_back(i);
  const int nf = int(free.size());
  Eigen::MatrixXd Sf(nf, nf), Rf(nf, 3);
  Coefficients Y = v;
  for (int i = 0; i < nf; ++i) {
    for (int j = 0; j < nf; ++j) Sf(i, j) = S(free[i], free[j]);
    Rf.row(i) = R.row(free[i]);
    for (int h : held) Rf.row(i) -= S(free[i], h) * v.row(h);
  }
  const Eigen::MatrixXd Xf = Sf.llt().solve(Rf);
  for (int i = 0; i < nf; ++i) Y.row(free[i]) = Xf.row(i);
  return Y;
}

// Functions whose row is empty (a pinch) keep their value exactly, and the others solve the
// system without them, as eliminating them would (dense reference), with and without a locked
// boundary function. They are held in place, so the pattern the solver sees does not change
// with the set of empty rows: the multigrid builds its Galerkin pattern once over steps whose
// empty rows differ (it rebuilt it every such step when they were eliminated).
TEST(ReducedSystem, EmptyRowsKeepTheirValueWithoutChangingThePattern) {
  const std::vector<std::set<int>> steps = {{5}, {7, 8}, {}, {20, 3}, {5}};
  for (const std::vector<int>& locked : {std::vector<int>{}, std::vector<int>{0}}) {
    SCOPED_TRACE(locked.size());
    ChainBasis basis(12, locked);
    CholmodSolver cholmod;
    MultigridOptions cycled;
    cycled.cycles = 300;
    cycled.tolerance = 1e-13;
    MultigridSolver multigrid(cycled);
    ReducedSystem direct(basis, cholmod), cycles(basis, multigrid);
    const Coefficients x = basis.initial_coefficients();
    const double a = 1.0, b = 1e-2;
    Coefficients R = 0.5 * x;
    R.col(1).array() += 1.0;
    for (const auto& empty : steps) {
      basis.set_empty(empty);
      std::set<int> held(empty);
      held.insert(locked.begin(), locked.end());
      const Coefficients reference = eliminated_solution(basis, a, b, R, x, held);
      const Coefficients y = direct.solve(a, b, R, x, x);
      ASSERT_TRUE(direct.report().ok()) << direct.report().message;
      EXPECT_EQ(direct.num_fixed(), held.size());
      EXPECT_LT((y - reference).norm(), 1e-12 * reference.norm());
      for (int i : held) EXPECT_EQ(y.row(i), x.row(i)) << "held function " << i;
      // Plain cycles to convergence, from zero: the same solution.
      const Coefficients z = cycles.solve(a, b, R, x, Coefficients::Zero(x.rows(), 3));
      ASSERT_TRUE(cycles.report().ok()) << cycles.report().message;
      EXPECT_LT((z - reference).norm(), 1e-10 * reference.norm());
      for (int i : held) EXPECT_EQ(z.row(i), x.row(i)) << "held function " << i;
    }
    EXPECT_EQ(multigrid.symbolic_builds(), 1);
  }
}

}  // namespace
}  // namespace mcf
