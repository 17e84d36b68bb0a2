#include "solvers/multigrid.h"

#include "solvers/multigrid_state.h"

#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>

namespace mcf {

static_assert(multigrid_detail::kTile == MultigridSolver::tile_size,
              "solvers/level_ordering.h tiles levels as the solver stores them");

// The solver's state and its parts: set-up (solvers/multigrid_setup.cpp), cycle
// (solvers/multigrid_cycle.cpp), smoother (solvers/smoother.h), Galerkin product
// (solvers/galerkin.h), internal numbering (solvers/level_ordering.h).
using namespace multigrid_detail;

struct MultigridSolver::Impl : MultigridState {};

// ------------------------------------------------------------------------------------------

MultigridSolver::MultigridSolver(MultigridOptions options)
    : options_(options), impl_(std::make_unique<Impl>()) {}
MultigridSolver::~MultigridSolver() = default;
MultigridSolver::MultigridSolver(MultigridSolver&&) noexcept = default;
MultigridSolver& MultigridSolver::operator=(MultigridSolver&&) noexcept = default;

std::string MultigridSolver::name() const {
  return std::string("multigrid-") + to_string(options_.cycle);
}

int MultigridSolver::levels() const {
  return impl_->ready ? int(impl_->levels.size()) : 0;
}
SparseMatrix MultigridSolver::level_matrix(int l) const {
  const auto& L = impl_->levels.at(std::size_t(l));
  return permuted(L.A, L.perm, L.inv, true);  // back to the caller's numbering
}
const SparseMatrix& MultigridSolver::finest_matrix() const {
  Impl& m = *impl_;
  if (m.levels.empty()) throw std::logic_error("MultigridSolver::finest_matrix before set_matrix");
  const auto& L = m.levels.back();
  if (m.finest_from.empty()) {
    // Each entry's position as its value, moved as level_matrix moves the values: exact in a
    // double up to 2^53 entries.
    SparseMatrix positions = L.A;
    for (Eigen::Index p = 0; p < positions.nonZeros(); ++p) positions.valuePtr()[p] = double(p);
    m.finest = permuted(positions, L.perm, L.inv, true);
    m.finest_from.resize(std::size_t(m.finest.nonZeros()));
    for (Eigen::Index p = 0; p < m.finest.nonZeros(); ++p)
      m.finest_from[std::size_t(p)] = int(m.finest.valuePtr()[p]);
    m.finest_call = -1;
  }
  if (m.finest_call != m.calls) {
    const double* from = L.A.valuePtr();
    double* to = m.finest.valuePtr();
    const int* where = m.finest_from.data();
    for_rows(int(m.finest.nonZeros()), [&](int b, int e) {
      for (int p = b; p < e; ++p) to[p] = from[where[p]];
    });
    m.finest_call = m.calls;
  }
  return m.finest;
}
bool MultigridSolver::level_is_coloured(int l) const {
  return impl_->levels.at(std::size_t(l)).coloured;
}
bool MultigridSolver::level_has_compact_smoother(int l) const {
  const auto& L = impl_->levels.at(std::size_t(l));
  return !L.smoother.empty();
}
std::vector<int> MultigridSolver::relaxation_blocks(int l) const {
  const auto& L = impl_->levels.at(std::size_t(l));
  std::vector<int> block(std::size_t(L.n()), 0);
  if (!L.coloured) {
    for (int q = 0; q < L.blocks(); ++q)
      for (int r = L.block_first(q); r < L.block_last(q); ++r)
        block[std::size_t(old_index(L.perm, r))] = q;
    return block;
  }
  // Block membership as the sweep itself walks it (for_block_segments), not re-derived here.
  for (int q = 0; q < L.blocks(); ++q)
    for_block_segments(L, q, false, [&](int r0, int r1) {
      for (int r = r0; r < r1; ++r) block[std::size_t(old_index(L.perm, r))] = q;
    });
  return block;
}
std::vector<int> MultigridSolver::relaxation_order(int l, bool reverse) const {
  const auto& L = impl_->levels.at(std::size_t(l));
  return multigrid_detail::relaxation_order(L, L.n(), reverse);
}
std::int64_t MultigridSolver::symbolic_builds() const {
  return impl_->symbolic_builds;
}
std::int64_t MultigridSolver::numeric_builds() const {
  return impl_->numeric_builds;
}

std::int64_t MultigridSolver::lagged_refreshes() const {
  return impl_->lagged_refreshes;
}
std::int64_t MultigridSolver::term_products() const {
  return impl_->term_products;
}
std::int64_t MultigridSolver::pattern_comparisons() const {
  return impl_->pattern_comparisons;
}
std::vector<MultigridLevelWork> MultigridSolver::level_work() const {
  return impl_->work;
}
void MultigridSolver::reset_level_work() {
  for (auto& w : impl_->work) w = MultigridLevelWork{};
}
SolveReport MultigridSolver::set_matrix(const SparseMatrix& A, HierarchyView hierarchy) {
  return set_levels(A, nullptr, hierarchy);
}

SolveReport MultigridSolver::set_matrix_sum(const MatrixSum& sum, HierarchyView hierarchy) {
  if (!summable(sum)) return LinearSolver::set_matrix_sum(sum, hierarchy);  // the general sum
  return set_levels(sum.M, &sum, hierarchy);
}

SolveReport MultigridSolver::set_levels(const SparseRef& A, const MatrixSum* sum,
                                        HierarchyView hierarchy) {
  return impl_->set_up(A, sum, hierarchy, options_);
}

SolveReport MultigridSolver::solve_in_place(const ConstMatrixRef& B, MatrixRef X) {
  return impl_->solve(B, X, options_);
}

void MultigridSolver::precondition(const Eigen::MatrixXd& r, Eigen::MatrixXd& z) {
  impl_->precondition(r, z, options_);
}

std::int64_t MultigridSolver::level_sweep_entries(int l) const {
  const auto& L = impl_->levels.at(std::size_t(l));
  std::int64_t diagonal = 0;
  for (int p : L.diag_pos) diagonal += p >= 0 ? 1 : 0;
  return std::int64_t(L.A.nonZeros()) - diagonal;
}
int MultigridSolver::level_sweep_entry_bytes(int l) const {
  const auto& L = impl_->levels.at(std::size_t(l));
  if (L.smoother.empty()) return int(sizeof(int) + sizeof(double));
  return int(sizeof(std::int16_t) + (L.smoother.aligned ? sizeof(double) : sizeof(float)));
}
std::int64_t MultigridSolver::coarsest_factor_nonzeros() const {
  const Impl& m = *impl_;
  if (!m.ready || m.coarse_pinv.size() > 0) return 0;
  return std::int64_t(m.ldlt.matrixL().nestedExpression().nonZeros()) + m.levels.front().n();
}

void MultigridSolver::run_kernel(MultigridKernel kernel, int l, int columns) {
  Impl& m = *impl_;
  if (!m.ready) throw std::logic_error("MultigridSolver::run_kernel before set_matrix");
  const int top = int(m.levels.size()) - 1;
  const bool transfer =
      kernel == MultigridKernel::restriction || kernel == MultigridKernel::prolongation;
  if (l < 0 || l > top || (transfer && l == 0) ||
      (kernel == MultigridKernel::coarsest_solve && l != 0))
    throw std::invalid_argument("MultigridSolver::run_kernel: no such level for this kernel");
  if (columns <= 0) return;
  m.ensure_buffers(columns);
  switch (kernel) {
    case MultigridKernel::forward_sweep:
      m.sweep(l, false);
      break;
    case MultigridKernel::reverse_sweep:
      m.sweep(l, true);
      break;
    case MultigridKernel::residual:
      m.residual(l);
      break;
    case MultigridKernel::restriction:
      m.restrict_residual(l);
      break;
    case MultigridKernel::prolongation:
      m.prolongate(l);
      break;
    case MultigridKernel::coarsest_solve:
      m.coarse_solve();
      break;
  }
}

void MultigridSolver::gauss_seidel(int l, const Eigen::MatrixXd& B, Eigen::MatrixXd& X, int sweeps,
                                   bool reverse) {
  Impl& m = *impl_;
  if (!m.ready) throw std::logic_error("MultigridSolver::gauss_seidel before set_matrix");
  auto& L = m.levels.at(std::size_t(l));
  if (B.rows() != L.n() || X.rows() != L.n() || X.cols() != B.cols())
    throw std::invalid_argument("MultigridSolver::gauss_seidel: wrong size");
  const int k = int(B.cols());
  if (k == 0) return;
  m.ensure_buffers(k);
  m.load(L, L.b, B);
  m.load(L, L.x, X);
  for (int i = 0; i < sweeps; ++i) m.sweep(l, reverse);
  m.store(L, L.x, X);
}

}  // namespace mcf
