#pragma once
// The preconditioner axis: one row per `solver.preconditioner` of the solvers whose row says
// uses_preconditioner (CG).

#include "config/config_values.h"
#include "config/memory_model.h"
#include "config/named_table.h"
#include "solvers/linear_solver.h"
#include "solvers/pcg_solver.h"

#include <functional>
#include <memory>
#include <string>

namespace mcf {

struct PreconditionerRow {
  std::string name;
  std::string help;
  /// CG with this preconditioner; `pcg` holds the tolerance and the iteration cap.
  std::function<std::unique_ptr<LinearSolver>(const SolverConfig&, PcgOptions pcg)> make;
  /// Bytes beyond the system matrix (required, as for solvers).
  std::function<double(const SystemFigures&)> memory;
  bool needs_hierarchy = false;  ///< a geometric multigrid cycle
};

const NamedTable<PreconditionerRow>& preconditioner_table();
/// Throws std::logic_error for a row without a factory or memory model, or a name taken.
void register_preconditioner(PreconditionerRow row);
const PreconditionerRow& preconditioner_row(const std::string& name);

}  // namespace mcf
