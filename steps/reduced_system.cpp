#include "steps/reduced_system.h"

#include "core/parallel.h"
#include "solvers/symmetric_multiply.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <stdexcept>
#include <string>

namespace mcf {

ReducedSystem::ReducedSystem(const Basis& basis, LinearSolver& solver)
    : basis_(basis),
      solver_(solver),
      base_fixed_(basis.locked_functions()),
      full_key_(new_pattern_key()) {
  std::sort(base_fixed_.begin(), base_fixed_.end());
}

bool ReducedSystem::shares_pattern(const SparseRef& M, const SparseRef& K) {
  // Checked once: the pattern never changes while this object lives.
  if (shares_pattern_ < 0) shares_pattern_ = same_pattern(M, K) ? 1 : 0;
  return shares_pattern_ == 1;
}

Coefficients ReducedSystem::solve(double a, double b, const Coefficients& R,
                                  const Coefficients& fixed_values, const Coefficients& warm,
                                  const ExtraTerm* extra, const Passes* passes) {
  passes_ = passes ? *passes : Passes{0.0, 1};
  // Views: no copies (the bases keep both on one pattern's index arrays).
  const SparseView M = basis_.mass();
  const SparseView K = basis_.stiffness();
  const MatrixSum terms = extra ? MatrixSum(a, M, b, K, extra->s, extra->S) : MatrixSum(a, M, b, K);
  // The system a M + b K [+ s S]. Bases assemble their matrices on one pattern: then it is a
  // value-wise sum, and it is formed here only when functions are held (below); otherwise the
  // solver forms it itself (set_matrix_sum), so no copy of it, as large as M, is kept here.
  const bool shared = shares_pattern(M, K) && (!extra || same_pattern(M, extra->S));
  if (!shared) sum_ = general_sum(terms);
  const std::vector<int> empty = empty_rows(a, b, M, K, shared);
  fixed_.clear();
  std::set_union(base_fixed_.begin(), base_fixed_.end(), empty.begin(), empty.end(),
                 std::back_inserter(fixed_));

  // The basis's pattern is fixed while this object lives (a rebuilt basis gets a new
  // ReducedSystem), so a pattern key lets the solver skip comparing it each step. No key when M
  // and K have different patterns: then sum_'s pattern depends on whether b is 0.
  const HierarchyView view{basis_.prolongations(), basis_.colours(), shared ? full_key_ : 0};
  if (fixed_.empty()) return solve_whole(terms, shared, view, R, warm);
  if (shared) {
    if (sum_.nonZeros() != M.nonZeros() || sum_.rows() != M.rows())
      sum_ = M;  // M's pattern is fixed
    sum_on_pattern(terms, sum_);
  }
  Anchors anchors = hold_in_place(empty, extra != nullptr);
  // Copies of R and the warm start only when rows are held in place (an open surface's steps
  // without a pinch read the caller's).
  Coefficients R_held, warm_held;
  if (!anchors.anchored.empty()) {
    R_held = R;
    warm_held = warm;
    for (int i : anchors.anchored) {
      R_held.row(i) = anchors.d * fixed_values.row(i);
      warm_held.row(i) = fixed_values.row(i);
    }
  }
  const Coefficients& R_in = anchors.anchored.empty() ? R : R_held;
  const Coefficients& warm_in = anchors.anchored.empty() ? warm : warm_held;
  Coefficients X;
  if (anchors.eliminated.empty()) {
    reduction_valid_ = false;
    report_ = solver_.set_matrix(sum_, view);
    X = std::move(warm_held);  // anchored is not empty here: fixed_ is
    solve_after_set(R_in, X);
  } else {
    X = solve_reduced(std::move(anchors.eliminated), shared, view, R_in, warm_in, fixed_values);
  }
  // The held coefficients exactly (the solve returns them to rounding).
  for (int i : anchors.anchored) X.row(i) = fixed_values.row(i);
  return X;
}

std::vector<int> ReducedSystem::empty_rows(double a, double b, const SparseView& M,
                                           const SparseView& K, bool shared) const {
  // Rows that received no contribution this step (every entry of a M + b K zero; by symmetry
  // their columns are zero too), apart from the basis's locked functions.
  std::vector<int> empty;
  const int* outer = shared ? M.outerIndexPtr() : sum_.outerIndexPtr();
  const double* m = shared ? M.valuePtr() : nullptr;
  const double* k = shared ? K.valuePtr() : nullptr;
  const double* v = shared ? nullptr : sum_.valuePtr();
  for (Eigen::Index c = 0; c < M.rows(); ++c) {
    bool is_empty = true;
    for (int p = outer[c]; p < outer[c + 1] && is_empty; ++p)
      is_empty = (shared ? sum_entry(a, m[p], b, k[p]) : v[p]) == 0.0;
    if (is_empty && !std::binary_search(base_fixed_.begin(), base_fixed_.end(), int(c)))
      empty.push_back(int(c));
  }
  return empty;
}

Coefficients ReducedSystem::solve_whole(const MatrixSum& terms, bool shared, HierarchyView view,
                                        const Coefficients& R, const Coefficients& warm) {
  if (shared) {
    sum_ = SparseMatrix();  // held functions may have needed it; now it is the solver's
    report_ = solver_.set_matrix_sum(terms, view);
  } else {
    report_ = solver_.set_matrix(sum_, view);
  }
  Coefficients X = warm;  // solved in place: no n x 3 copies in and out (31 MB each at depth 9)
  solve_after_set(R, X);
  return X;
}

ReducedSystem::Anchors ReducedSystem::hold_in_place(const std::vector<int>& empty,
                                                    bool eliminate_all) {
  // An empty row is held in place (the paper's anchoring, Section 5.3: the coefficient keeps
  // its value): its diagonal becomes d and its right-hand side d times the held value. Its
  // column is zero, so no other unknown sees it and the solution of the others is the one of
  // the system without it, while the pattern, and so the solver's symbolic work (Galerkin
  // pattern, CHOLMOD's analysis), stays that of every other step. Eliminating the row instead
  // changes the pattern whenever the set of empty rows does, which through a pinch or with
  // the 1-point rule is nearly every step (docs/benchmarks.md, "Measurements behind
  // implementation choices"). d is the mean
  // diagonal of the other rows, so the coarse operators the row feeds stay of the usual scale.
  // One pass over the columns: each empty row's diagonal position, and the mean of the others'
  // positive diagonal entries. Rows without a stored diagonal cannot be held in place: they are
  // eliminated; so are all of them when an extra term couples them to their neighbours
  // (eliminate_all: their columns are not zero).
  Anchors anchors;
  anchors.eliminated = base_fixed_;
  if (!empty.empty()) {
    std::vector<int> anchored_diagonal;
    const int* outer = sum_.outerIndexPtr();
    const int* inner = sum_.innerIndexPtr();
    const double* v = sum_.valuePtr();
    double total = 0;
    Eigen::Index count = 0;
    std::size_t e = 0;  // empty is sorted
    for (Eigen::Index c = 0; c < sum_.rows(); ++c) {
      const int* at = std::lower_bound(inner + outer[c], inner + outer[c + 1], int(c));
      const int diagonal = at != inner + outer[c + 1] && *at == c ? int(at - inner) : -1;
      if (e < empty.size() && empty[e] == c) {
        if (diagonal < 0 || eliminate_all) {
          anchors.eliminated.push_back(int(c));
        } else {
          anchors.anchored.push_back(int(c));
          anchored_diagonal.push_back(diagonal);
        }
        ++e;
      } else if (diagonal >= 0 && v[diagonal] > 0) {
        total += v[diagonal];
        ++count;
      }
    }
    if (count > 0 && std::isfinite(total / double(count))) anchors.d = total / double(count);
    for (int p : anchored_diagonal) sum_.valuePtr()[p] = anchors.d;
  }
  std::sort(anchors.eliminated.begin(), anchors.eliminated.end());
  return anchors;
}

Coefficients ReducedSystem::solve_reduced(std::vector<int> eliminated, bool shared,
                                          const HierarchyView& view, const Coefficients& R,
                                          const Coefficients& warm,
                                          const Coefficients& fixed_values) {
  // Only a change of the eliminated set (the basis's locked functions, fixed for the basis's
  // life) needs a new reduction (and a new key, rebuild_reduction).
  if (!reduction_valid_ || eliminated != eliminated_) {
    eliminated_ = std::move(eliminated);
    rebuild_reduction(sum_);
  }
  // Reduced matrix values.
  {
    double* rv = reduced_.valuePtr();
    const double* sv = sum_.valuePtr();
    const int* src = source_nz_.data();
    parallel_for_indices<std::size_t>(source_nz_.size(), 1 << 14,
                                      [&](std::size_t i) { rv[i] = sv[src[i]]; });
  }
  // Right-hand side: R_f - S_fl Y_l.
  Coefficients Yfixed = Coefficients::Zero(sum_.rows(), 3);
  for (int i : eliminated_) Yfixed.row(i) = fixed_values.row(i);
  const Coefficients coupling = symmetric_multiply(sum_, Yfixed);  // S is symmetric
  const Eigen::Index nf = Eigen::Index(free_.size());
  Eigen::MatrixXd Rf(nf, 3), Xf(nf, 3);
  for (Eigen::Index i = 0; i < nf; ++i) {
    Rf.row(i) = R.row(free_[i]) - coupling.row(free_[i]);
    Xf.row(i) = warm.row(free_[i]);
  }
  if (nf == 0) {
    // Every function is held (a mesh whose vertices all lie on its boundary): the solution is
    // the held values, and no solver is asked to factorize or cycle on an empty matrix, which
    // each would report in its own way as a failure.
    report_ = SolveReport{};
    report_.message = "nothing free to move: every function is held";
    return Yfixed;
  }
  HierarchyView reduced_view;
  if (!view.empty()) reduced_view = HierarchyView{&prolongations_, &colours_};
  reduced_view.pattern_key = shared ? reduced_key_ : 0;
  report_ = solver_.set_matrix(reduced_, reduced_view);
  solve_after_set(Rf, Xf);
  Coefficients Y = Yfixed;
  for (Eigen::Index i = 0; i < nf; ++i) Y.row(free_[i]) = Xf.row(i);
  return Y;
}

void ReducedSystem::rebuild_reduction(const SparseMatrix& S) {
  const Eigen::Index n = S.rows();
  reduced_of_.assign(n, 0);
  for (int i : eliminated_) reduced_of_[i] = -1;
  free_.clear();
  for (Eigen::Index i = 0; i < n; ++i)
    if (reduced_of_[i] == 0) {
      reduced_of_[i] = int(free_.size());
      free_.push_back(int(i));
    }
  const Eigen::Index nf = Eigen::Index(free_.size());
  std::vector<int> outer(nf + 1, 0), inner;
  source_nz_.clear();
  for (Eigen::Index j = 0; j < nf; ++j) {
    const int c = free_[j];
    for (int p = S.outerIndexPtr()[c]; p < S.outerIndexPtr()[c + 1]; ++p) {
      const int r = reduced_of_[S.innerIndexPtr()[p]];
      if (r < 0) continue;
      inner.push_back(r);
      source_nz_.push_back(p);
    }
    outer[j + 1] = int(inner.size());
  }
  const std::vector<double> zeros(inner.size(), 0.0);
  reduced_ = Eigen::Map<const SparseMatrix>(nf, nf, Eigen::Index(inner.size()), outer.data(),
                                            inner.data(), zeros.data());
  reduced_.makeCompressed();

  // Restrict the finest prolongation's rows (and the finest colours) to the free functions; on
  // coarser levels the correction at a fixed function is then zero (docs/octree-multigrid.md "Held
  // functions").
  prolongations_.clear();
  colours_.clear();
  if (basis_.prolongations() && !basis_.prolongations()->empty()) {
    prolongations_ = *basis_.prolongations();
    const SparseMatrix& P = prolongations_.back();
    SparseMatrix selector(nf, n);
    std::vector<Eigen::Triplet<double>> t;
    t.reserve(nf);
    for (Eigen::Index i = 0; i < nf; ++i) t.emplace_back(int(i), free_[i], 1.0);
    selector.setFromTriplets(t.begin(), t.end());
    prolongations_.back() = selector * P;
    prolongations_.back().makeCompressed();
    if (basis_.colours()) {
      colours_ = *basis_.colours();
      std::vector<std::uint8_t> finest(nf);
      for (Eigen::Index i = 0; i < nf; ++i) finest[i] = colours_.back()[free_[i]];
      colours_.back() = std::move(finest);
    }
  }
  reduced_key_ = new_pattern_key();
  reduction_valid_ = true;
}

void ReducedSystem::solve_after_set(const ConstMatrixRef& R, MatrixRef X) {
  if (!report_.ok()) return;
  // set_matrix's note on a matrix it accepted (a semi-definite coarsest level solved by its
  // pseudo-inverse, a level without a valid colouring) is kept in the solve's report: the flow
  // records report().message, and the solve's own report used to replace the note unseen.
  std::string note = std::move(report_.message);
  report_ = solver_.solve(R, X);
  for (int pass = 1;
       pass < passes_.max && report_.ok() && !(report_.relative_residual <= passes_.tolerance);
       ++pass) {
    SolveReport more = solver_.solve(R, X);
    more.iterations += report_.iterations;
    more.residuals.insert(more.residuals.begin(), report_.residuals.begin(),
                          report_.residuals.end());
    report_ = std::move(more);
  }
  report_.message = joined_messages(note, report_.message);
}

}  // namespace mcf
