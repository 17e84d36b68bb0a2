#include "solvers/multigrid_state.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <utility>

namespace mcf::multigrid_detail {
namespace {

// The cycle's kernels besides the sweeps (solvers/smoother.h), on the same interleaved buffers.

/// r = b - A x (rows [begin, end)), columns o..o+3.
MCF_KERNEL_INLINE void residual_rows(const Csc& A, const double* b, const double* x, double* r,
                                     std::size_t s, int o, int begin, int end) {
  for (int i = begin; i < end; ++i) {
    const std::size_t ii = std::size_t(i) * s + o;
    v4 acc0 = load4(b + ii), acc1 = splat(0.0);
    gather_sub(A, x, s, o, A.outer[i], A.outer[i + 1], acc0, acc1);
    store4(r + ii, acc0 + acc1);
  }
}

/// y = Mᵀ v (or y += Mᵀ v when Add) on output rows [begin, end) = columns of M (gather along
/// columns, so parallel output ranges never write the same entry), columns o..o+3.
template <bool Add>
MCF_KERNEL_INLINE void transpose_rows(const Csc& M, const double* v, double* y, std::size_t s,
                                      int o, int begin, int end) {
  for (int J = begin; J < end; ++J) {
    v4 acc0 = splat(0.0), acc1 = splat(0.0);
    gather_sub(M, v, s, o, M.outer[J], M.outer[J + 1], acc0, acc1);
    double* yJ = y + std::size_t(J) * s + o;
    const v4 sum = -(acc0 + acc1);
    store4(yJ, Add ? load4(yJ) + sum : sum);
  }
}

// Two clock reads per level visit (a W-cycle at depth 9 makes 384): noise next to the sweeps.
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

}  // namespace

void MultigridState::ensure_buffers(int cols) {
  if (cols == k) return;
  k = cols;
  s = (std::size_t(k) + 3) / 4 * 4;
  for (auto& L : levels) {
    const std::size_t sz = std::size_t(L.n()) * s;
    L.x.assign(sz, 0.0);
    L.b.assign(sz, 0.0);
    L.r.assign(sz, 0.0);
  }
  coarse_rhs.resize(levels.front().n(), k);
  coarse_sol.resize(levels.front().n(), k);
}

void MultigridState::sweep(int l, bool reverse) {
  Level& L = levels[std::size_t(l)];
  gauss_seidel_sweep(L, Csc(L.A), L.smoother, L.diag_pos.data(), L.inv_diag.data(), L.b.data(),
                     L.x.data(), s, reverse);
}

void MultigridState::residual(int l) {
  Level& L = levels[std::size_t(l)];
  const Csc A(L.A);
  for (int o = 0; o < int(s); o += 4)
    for_rows(A.cols, [&](int b, int e) {
      residual_rows(A, L.b.data(), L.x.data(), L.r.data(), s, o, b, e);
    });
}

void MultigridState::coarse_solve() {
  Level& L = levels.front();
  const int n = L.n();
  if (coarse_pinv.size() == 0) {
    // The padding columns of b are zero, so those of x come out zero, as everywhere else.
    solve_interleaved(coarse_factor, L.b.data(), L.x.data(), s, coarse_work);
    return;
  }
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < k; ++c) coarse_rhs(i, c) = L.b[std::size_t(i) * s + std::size_t(c)];
  coarse_sol.noalias() = coarse_pinv * coarse_rhs;
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < k; ++c) L.x[std::size_t(i) * s + std::size_t(c)] = coarse_sol(i, c);
}

void MultigridState::restrict_residual(int l) {
  const Level& F = levels[std::size_t(l)];
  Level& C = levels[std::size_t(l) - 1];
  const Csc P(C.P);
  for (int o = 0; o < int(s); o += 4)
    for_rows(P.cols, [&](int b, int e) {
      transpose_rows<false>(P, F.r.data(), C.b.data(), s, o, b, e);
      for (int J = b; J < e; ++J) store4(C.x.data() + std::size_t(J) * s + o, splat(0.0));
    });
}

void MultigridState::zero_iterate(Level& L) {
  double* x = L.x.data();
  for_rows(L.n(),
           [&](int b, int e) { std::fill(x + std::size_t(b) * s, x + std::size_t(e) * s, 0.0); });
}

void MultigridState::prolongate(int l) {
  Level& F = levels[std::size_t(l)];
  const Level& C = levels[std::size_t(l) - 1];
  const Csc PT(C.PT);
  for (int o = 0; o < int(s); o += 4)
    for_rows(PT.cols,
             [&](int b, int e) { transpose_rows<true>(PT, C.x.data(), F.x.data(), s, o, b, e); });
}

void MultigridState::cycle(int l, const MultigridOptions& opt) {
  const auto t0 = Clock::now();
  MultigridLevelWork& w = work[std::size_t(l)];
  ++w.visits;
  if (l == 0) {
    coarse_solve();
    w.seconds += since(t0);
    return;
  }
  for (int i = 0; i < opt.pre_smooth; ++i) sweep(l, false);
  residual(l);
  restrict_residual(l);  // and C.x = 0
  // γ = 2 for W; an exact coarsest solve is never repeated (it would change nothing).
  const int gamma = (opt.cycle == MultigridCycle::W && l - 1 > 0) ? 2 : 1;
  const auto tc = Clock::now();
  for (int g = 0; g < gamma; ++g) cycle(l - 1, opt);
  const double coarser = since(tc);  // the recursion's time, not this level's own
  prolongate(l);
  for (int i = 0; i < opt.post_smooth; ++i) sweep(l, true);
  w.seconds += since(t0) - coarser;
}

void MultigridState::correction_cycle(const MultigridOptions& opt, bool have_r) {
  const int top = int(levels.size()) - 1;
  Level& F = levels.back();
  if (!have_r) residual(top);
  if (F.saved_b.size() != F.b.size()) F.saved_b.assign(F.b.size(), 0.0);
  if (F.saved_x.size() != F.x.size()) F.saved_x.assign(F.x.size(), 0.0);
  std::swap(F.b, F.saved_b);  // b kept
  std::swap(F.b, F.r);        // the cycle's right-hand side: the residual
  std::swap(F.x, F.saved_x);  // x kept
  zero_iterate(F);
  cycle(top, opt);
  double* x = F.x.data();
  const double* x0 = F.saved_x.data();
  for_rows(int(F.x.size()), [&](int b, int e) {
    for (int i = b; i < e; ++i) x[i] = x0[i] + x[i];
  });
  std::swap(F.b, F.saved_b);  // b back
}

double MultigridState::relative_residual(const Eigen::VectorXd& bnorm, bool keep) {
  Level& L = levels.back();
  const Csc A(L.A);
  std::vector<double> rn(s, 0.0);
  for (int o = 0; o < int(s); o += 4) {
    struct Acc {
      v4 v = {0.0, 0.0, 0.0, 0.0};
    };
    const Acc sum = tbb::parallel_deterministic_reduce(
        tbb::blocked_range<int>(0, A.cols, 4096), Acc{},
        [&](const tbb::blocked_range<int>& r, Acc acc) {
          for (int i = r.begin(); i < r.end(); ++i) {
            v4 res0 = load4(L.b.data() + std::size_t(i) * s + o), res1 = splat(0.0);
            gather_sub(A, L.x.data(), s, o, A.outer[i], A.outer[i + 1], res0, res1);
            const v4 res = res0 + res1;
            if (keep) store4(L.r.data() + std::size_t(i) * s + o, res);
            acc.v += res * res;
          }
          return acc;
        },
        [](Acc a, const Acc& b) {
          a.v += b.v;
          return a;
        });
    for (int c = 0; c < 4; ++c) rn[std::size_t(o + c)] = sum.v[c];
  }
  double worst = 0.0;
  for (int c = 0; c < k; ++c) {
    const double r = std::sqrt(rn[std::size_t(c)]);
    const double rel = bnorm[c] > 0.0 ? r / bnorm[c] : r;
    if (std::isnan(rel)) return rel;
    worst = std::max(worst, rel);
  }
  return worst;
}

void MultigridState::load(const Level& L, Buffer& dst, const ConstMatrixRef& src) {
  for_rows(int(src.rows()), [&](int b, int e) {
    for (int r = b; r < e; ++r) {
      const int i = old_index(L.perm, r);
      for (int c = 0; c < k; ++c) dst[std::size_t(r) * s + std::size_t(c)] = src(i, c);
    }
  });
}

void MultigridState::store(const Level& L, const Buffer& src, MatrixRef dst) {
  for_rows(int(dst.rows()), [&](int b, int e) {
    for (int r = b; r < e; ++r) {
      const int i = old_index(L.perm, r);
      for (int c = 0; c < k; ++c) dst(i, c) = src[std::size_t(r) * s + std::size_t(c)];
    }
  });
}

SolveReport MultigridState::solve(const ConstMatrixRef& B, MatrixRef X,
                                  const MultigridOptions& options) {
  SolveReport rep;
  if (!ready) {
    rep.status = SolveStatus::failed;
    rep.message = "set_matrix was not called or failed";
    return rep;
  }
  const int n = levels.back().n();
  if (B.rows() != n) {
    rep.status = SolveStatus::failed;
    rep.message = "right-hand side has the wrong number of rows";
    return rep;
  }
  if (options.cycles < 1) {
    rep.status = SolveStatus::failed;
    rep.message = "MultigridOptions::cycles must be at least 1";
    return rep;
  }
  const int cols = int(B.cols());
  if (cols == 0) return rep;
  ensure_buffers(cols);
  auto& fine = levels.back();
  load(fine, fine.b, B);
  load(fine, fine.x, X);
  const Eigen::VectorXd bnorm = B.colwise().norm().transpose();
  const int top = int(levels.size()) - 1;
  const double tol = options.tolerance;

  const bool measure_start = tol > 0.0 || options.measure_contraction;
  // Mixed precision: each cycle runs on the correction of the residual that the previous
  // convergence check kept (correction_cycle).
  const bool mixed = fine_single && top > 0;
  double rel =
      measure_start ? relative_residual(bnorm, mixed) : std::numeric_limits<double>::infinity();
  bool have_r = measure_start && mixed;
  const double start = rel;
  if (tol > 0.0 && rel < tol) {
    rep.relative_residual = rel;
    return rep;
  }
  rep.status = SolveStatus::max_iterations;
  for (int c = 0; c < options.cycles; ++c) {
    if (mixed)
      correction_cycle(options, have_r);
    else
      cycle(top, options);
    const double before = rel;
    rel = relative_residual(bnorm, mixed);
    have_r = mixed;
    rep.residuals.push_back(rel);
    rep.iterations = c + 1;
    if (!std::isfinite(rel)) {
      rep.status = SolveStatus::numerical_issue;
      rep.message = "NaN or infinity in the multigrid iterate";
      break;
    }
    if (tol > 0.0 && rel < tol) {
      rep.status = SolveStatus::converged;
      break;
    }
    if (tol > 0.0 && options.give_up_ratio > 0.0 && rel > options.give_up_ratio * before) {
      char note[128];
      std::snprintf(note, sizeof note, "a cycle reduced the residual by only %.3g: stopped",
                    rel / before);
      rep.message = note;
      break;
    }
  }
  // Fixed work (no tolerance) ran its cycles without checking where they ended: max_iterations,
  // never `converged` (a guard that checks them against a bound says that:
  // solvers/multigrid_fallback.h), except on a single level, where the cycle is the direct solve.
  if (tol <= 0.0 && top == 0 && rep.iterations > 0 && std::isfinite(rel))
    rep.status = SolveStatus::converged;
  rep.relative_residual = rel;
  if (measure_start && rep.iterations > 0 && std::isfinite(rel) && std::isfinite(start) &&
      start > 0.0)
    rep.contraction = std::pow(rel / start, 1.0 / rep.iterations);
  store(fine, fine.x, X);
  return rep;
}

void MultigridState::precondition(const Eigen::MatrixXd& r, Eigen::MatrixXd& z,
                                  const MultigridOptions& options) {
  if (!ready) throw std::logic_error("MultigridSolver::precondition before set_matrix");
  const int n = levels.back().n();
  if (r.rows() != n) throw std::invalid_argument("MultigridSolver::precondition: wrong size");
  const int cols = int(r.cols());
  if (z.rows() != n || z.cols() != cols) z.resize(n, cols);
  if (cols == 0) return;
  ensure_buffers(cols);
  auto& fine = levels.back();
  load(fine, fine.b, r);
  zero_iterate(fine);
  cycle(int(levels.size()) - 1, options);
  store(fine, fine.x, z);
}

}  // namespace mcf::multigrid_detail
