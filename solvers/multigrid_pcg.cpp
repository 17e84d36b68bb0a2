#include "solvers/multigrid_pcg.h"

#include <string>
#include <utility>

namespace mcf {

MultigridPcgSolver::MultigridPcgSolver(MultigridOptions cycle, PcgOptions pcg)
    : multigrid_(cycle), pcg_(pcg) {
  // A preconditioner must be symmetric for CG: equal pre- and post-smoothing sweeps, and the
  // cycle's post-smoother runs the colours in reverse (MultigridSolver::precondition).
  cycle.post_smooth = cycle.pre_smooth;
  multigrid_.set_options(cycle);
  pcg.preconditioner = PcgPreconditioner::external;
  pcg_.set_options(pcg);
  pcg_.set_preconditioner(
      [this](const Eigen::MatrixXd& r, Eigen::MatrixXd& z) { multigrid_.precondition(r, z); });
}

namespace {
// PCG's report with the preconditioner's note on the matrix (a semi-definite coarsest level,
// a level without colouring) in front of PCG's own: PCG's report alone dropped it.
SolveReport with_note(SolveReport preconditioner, SolveReport pcg) {
  pcg.message = joined_messages(preconditioner.message, pcg.message);
  return pcg;
}
}  // namespace

SolveReport MultigridPcgSolver::set_matrix(const SparseMatrix& A, HierarchyView hierarchy) {
  SolveReport r = multigrid_.set_matrix(A, hierarchy);
  if (!r.ok()) return r;
  return with_note(std::move(r), pcg_.set_matrix(A, hierarchy));
}

SolveReport MultigridPcgSolver::set_matrix_sum(const MatrixSum& sum, HierarchyView hierarchy) {
  SolveReport r = multigrid_.set_matrix_sum(sum, hierarchy);
  if (!r.ok()) return r;
  return with_note(std::move(r), pcg_.set_matrix_sum(sum, hierarchy));
}

}  // namespace mcf
