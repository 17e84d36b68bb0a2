#include "distributed/rank_block_cg.h"

#ifdef MCFBENCH_HAVE_PETSC

#include "distributed/comm.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace mcf::dist {

namespace {

/// Per column Σ_i u(i, c) v(i, c) over the owned rows of every rank, summed in rank order.
std::array<double, 3> column_dots(const std::vector<double>& u, const std::vector<double>& v) {
  std::vector<double> partial(3, 0.0);
  for (std::size_t i = 0; i < u.size(); i += 4)
    for (std::size_t c = 0; c < 3; ++c) partial[c] += u[i + c] * v[i + c];
  const std::vector<double> total = ordered_sum(partial);
  return {total[0], total[1], total[2]};
}

std::array<double, 3> column_norms(const double* u, std::size_t size) {
  std::vector<double> partial(3, 0.0);
  for (std::size_t i = 0; i < size; i += 4)
    for (std::size_t c = 0; c < 3; ++c) partial[c] += u[i + c] * u[i + c];
  const std::vector<double> total = ordered_sum(partial);
  return {std::sqrt(total[0]), std::sqrt(total[1]), std::sqrt(total[2])};
}

}  // namespace

std::array<double, 3> relative_residuals(RankMultigrid& multigrid, const double* B,
                                         const double* X) {
  const std::size_t size = 4 * std::size_t(multigrid.owned());
  std::vector<double> r(size);
  multigrid.apply(X, r.data());
  for (std::size_t i = 0; i < size; ++i) r[i] = B[i] - r[i];
  const std::array<double, 3> rn = column_norms(r.data(), size), bn = column_norms(B, size);
  std::array<double, 3> out{};
  for (int c = 0; c < 3; ++c)
    out[std::size_t(c)] =
        bn[std::size_t(c)] > 0 ? rn[std::size_t(c)] / bn[std::size_t(c)] : rn[std::size_t(c)];
  return out;
}

BlockCgReport block_cg(RankMultigrid& multigrid, const double* B, double* X,
                       std::array<bool, 3> active, double tolerance, int max_iterations) {
  BlockCgReport report;
  const std::size_t size = 4 * std::size_t(multigrid.owned());
  std::vector<double> r(size), z(size, 0.0), p(size), q(size);
  const std::array<double, 3> bn = column_norms(B, size);
  multigrid.apply(X, r.data());
  for (std::size_t i = 0; i < size; ++i) r[i] = B[i] - r[i];
  std::array<bool, 3> running{};
  const auto stop_done = [&](const std::array<double, 3>& rn) {
    bool any = false;
    for (std::size_t c = 0; c < 3; ++c) {
      if (running[c] && rn[c] <= tolerance * bn[c]) {
        running[c] = false;
        report.converged[c] = true;
      }
      any = any || running[c];
    }
    return any;
  };
  // A stopped column's lanes are zeroed before the cycle, so its z, p and steps stay zero.
  const auto mask = [&](std::vector<double>& v) {
    for (std::size_t c = 0; c < 3; ++c)
      if (!running[c])
        for (std::size_t i = c; i < size; i += 4) v[i] = 0.0;
  };
  running = active;
  if (!stop_done(column_norms(r.data(), size))) return report;
  const auto precondition = [&]() {
    mask(r);
    std::fill(z.begin(), z.end(), 0.0);
    multigrid.cycle(r.data(), z.data());
  };
  precondition();
  p = z;
  std::array<double, 3> rz = column_dots(r, z);
  for (int k = 1; k <= max_iterations; ++k) {
    multigrid.apply(p.data(), q.data());
    const std::array<double, 3> pq = column_dots(p, q);
    double alpha[4] = {0, 0, 0, 0};
    for (std::size_t c = 0; c < 3; ++c) {
      if (!running[c]) continue;
      if (!(pq[c] > 0)) {
        report.breakdown[c] = true;
        running[c] = false;
        continue;
      }
      alpha[c] = rz[c] / pq[c];
      report.iterations[c] = k;
    }
    for (std::size_t i = 0; i < size; i += 4)
      for (std::size_t c = 0; c < 3; ++c) {
        X[i + c] += alpha[c] * p[i + c];
        r[i + c] -= alpha[c] * q[i + c];
      }
    if (!stop_done(column_norms(r.data(), size))) break;
    precondition();
    const std::array<double, 3> rz_new = column_dots(r, z);
    double beta[4] = {0, 0, 0, 0};
    for (std::size_t c = 0; c < 3; ++c)
      if (running[c]) beta[c] = rz_new[c] / rz[c];
    for (std::size_t i = 0; i < size; i += 4)
      for (std::size_t c = 0; c < 3; ++c) p[i + c] = z[i + c] + beta[c] * p[i + c];
    rz = rz_new;
  }
  return report;
}

}  // namespace mcf::dist

#endif
