// Solvers by name (the rows of config/solver_registry.h) and solvers the caller defines: each
// definition becomes a row whose LinearSolver calls the caller's factory and solve.

#include "mcfbench/solver.h"

#include "api/detail.h"

#include "config/registry.h"
#include "config/solver_registry.h"

#include <map>
#include <memory>
#include <mutex>

namespace mcfbench {
namespace {

SolveInfo info_of(const mcf::SolveReport& r) {
  return {mcf::to_string(r.status), r.ok(), r.iterations, r.relative_residual, r.message};
}

/// The caller's definitions by name; a row looks its definition up when it makes a solver, so a
/// definition given again replaces the one later flows use.
struct Definitions {
  std::mutex lock;
  std::map<std::string, std::shared_ptr<const SolverDefinition>> by_name;
};

Definitions& definitions() {
  static Definitions d;
  return d;
}

std::shared_ptr<const SolverDefinition> definition_of(const std::string& name) {
  Definitions& d = definitions();
  const std::lock_guard<std::mutex> hold(d.lock);
  return d.by_name.at(name);
}

/// A solver the caller defined. The factory is called on every matrix whose pattern or values
/// differ from the last one's; the solve's answer is checked by its true residual, which the
/// report carries as a built-in direct solver's does.
class DefinedSolver final : public mcf::LinearSolver {
 public:
  explicit DefinedSolver(std::shared_ptr<const SolverDefinition> definition)
      : definition_(std::move(definition)) {}
  std::string name() const override { return definition_->name; }

  mcf::SolveReport set_matrix(const mcf::SparseMatrix& A, mcf::HierarchyView) override {
    mcf::SolveReport report;
    report.iterations = 0;
    if (solve_ && A.isCompressed() && A_.isCompressed() && mcf::same_pattern(A, A_) &&
        std::equal(A.valuePtr(), A.valuePtr() + A.nonZeros(), A_.valuePtr()))
      return report;  // the same matrix: its solve stands
    solve_ = nullptr;
    A_ = A;
    A_.makeCompressed();
    solve_ = definition_->factory(A_);
    if (!solve_) {
      report.status = mcf::SolveStatus::failed;
      report.message = definition_->name + ": the factory returned no solve function";
    }
    return report;
  }

 protected:
  mcf::SolveReport solve_in_place(const mcf::ConstMatrixRef& B, mcf::MatrixRef X) override {
    mcf::SolveReport report;
    if (!solve_) {
      report.status = mcf::SolveStatus::failed;
      report.message = definition_->name + ": solve before set_matrix";
      return report;
    }
    const DenseMatrix b = B;
    DenseMatrix x = X;
    solve_(b, x);
    if (x.rows() != B.rows() || x.cols() != B.cols()) {
      report.status = mcf::SolveStatus::failed;
      report.message = definition_->name + ": the solve returned " + std::to_string(x.rows()) +
                       " x " + std::to_string(x.cols()) + " for a right-hand side of " +
                       std::to_string(B.rows()) + " x " + std::to_string(B.cols());
      return report;
    }
    X = x;
    report.iterations = 1;
    const Eigen::MatrixXd R = B - A_ * X;
    mcf::report_true_residual(B, R, report);
    report.residuals = {report.relative_residual};
    return report;
  }

 private:
  std::shared_ptr<const SolverDefinition> definition_;
  mcf::SparseMatrix A_;
  SolveFunction solve_;
};

}  // namespace

struct Solver::Impl {
  std::unique_ptr<mcf::LinearSolver> solver;
};

Solver::Solver(const Options& options) : impl_(std::make_unique<Impl>()) {
  detail::translated([&] {
    const mcf::FlowConfig config = detail::flow_config(options, "(no mesh)", true);
    impl_->solver = mcf::make_solver(config.solver);
  });
}

Solver::~Solver() = default;
Solver::Solver(Solver&&) noexcept = default;
Solver& Solver::operator=(Solver&&) noexcept = default;

std::string Solver::name() const {
  return impl_->solver->name();
}

SolveInfo Solver::set_matrix(const SparseMatrix& A) {
  if (A.rows() != A.cols())
    throw InputError("solver: set_matrix: A is " + std::to_string(A.rows()) + " x " +
                     std::to_string(A.cols()) + ", not square");
  SparseMatrix compressed = A;
  compressed.makeCompressed();
  return info_of(impl_->solver->set_matrix(compressed));
}

SolveInfo Solver::solve(const DenseMatrix& B, DenseMatrix& X) {
  Eigen::MatrixXd x = X;
  const mcf::SolveReport report = impl_->solver->solve(Eigen::MatrixXd(B), x);
  X = x;
  return info_of(report);
}

void register_solver(SolverDefinition definition) {
  if (definition.name.empty()) throw InputError("register_solver: the solver needs a name");
  if (!definition.factory) throw InputError("register_solver: " + definition.name + ": no factory");
  // The solver table is read without a lock while a flow runs: it changes only between runs.
  if (detail::RunScope::inside())
    throw InputError("register_solver: " + definition.name +
                     ": called from inside a running flow or study; register solvers before");
  const std::lock_guard<std::mutex> quiet(detail::run_lock());  // another thread's run ends first
  Definitions& d = definitions();
  const std::lock_guard<std::mutex> hold(d.lock);
  const std::string name = definition.name;
  const bool defined = d.by_name.count(name) > 0;
  if (!defined && mcf::solver_table().find(name))
    throw InputError("register_solver: \"" + name +
                     "\" is a built-in solver's name; choose another");
  const bool iterative = definition.iterative;
  std::string help =
      definition.help.empty() ? "a solver registered by the program" : definition.help;
  d.by_name[name] = std::make_shared<const SolverDefinition>(std::move(definition));
  if (defined) return;  // the row is there; flows from now on make the new definition's solver
  mcf::SolverRow row;
  row.name = name;
  row.help = help;
  row.make = [name](const mcf::SolverConfig&) -> std::unique_ptr<mcf::LinearSolver> {
    return std::make_unique<DefinedSolver>(definition_of(name));
  };
  if (iterative)
    row.memory = [](const mcf::SolverConfig&, const mcf::SystemFigures& s) {
      return (12 * s.nonzeros_per_row + 6 * 8) * s.dimension;  // a copy of A, a few vectors
    };
  else
    row.memory = [](const mcf::SolverConfig&, const mcf::SystemFigures& s) {
      return (12 * s.nonzeros_per_row + s.factor_bytes_per_unknown) * s.dimension;  // A, a factor
    };
  row.iterative = iterative;
  mcf::register_solver(std::move(row));
}

}  // namespace mcfbench
