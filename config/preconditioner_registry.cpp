#include "config/preconditioner_registry.h"

#include "config/multigrid_params.h"
#include "solvers/multigrid_pcg.h"

#include <stdexcept>

namespace mcf {
namespace {

void check(const PreconditionerRow& row) {
  if (!row.make || !row.memory)
    throw std::logic_error("preconditioner \"" + row.name +
                           "\" registered without a factory or a memory model");
}

/// CG with one of PcgSolver's own preconditioners, which need nothing beyond a vector or the
/// incomplete factor (not counted: its fill is the matrix's).
PreconditionerRow built_in_pcg(std::string name, std::string help, PcgPreconditioner p) {
  return {std::move(name), std::move(help),
          [p](const SolverConfig&, PcgOptions o) -> std::unique_ptr<LinearSolver> {
            o.preconditioner = p;
            return std::make_unique<PcgSolver>(o);
          },
          [](const SystemFigures&) { return 0.0; }};
}

NamedTable<PreconditionerRow> built_in() {
  NamedTable<PreconditionerRow> t("preconditioner", check);
  PreconditionerRow multigrid{
      "multigrid", "one cycle of the basis's geometric multigrid",
      [](const SolverConfig& c, PcgOptions o) -> std::unique_ptr<LinearSolver> {
        MultigridOptions cycle = multigrid_options(c);
        cycle.cycles = 1;  // solver.cycles is refused here unless 1 (its default)
        cycle.tolerance = 0;
        return std::make_unique<MultigridPcgSolver>(cycle, o);
      },
      [](const SystemFigures& s) { return s.hierarchy_bytes_per_unknown * s.dimension; }};
  multigrid.needs_hierarchy = true;
  for (PreconditionerRow row :
       {built_in_pcg("none", "plain CG", PcgPreconditioner::none),
        built_in_pcg("jacobi", "the inverse diagonal", PcgPreconditioner::jacobi),
        built_in_pcg("ichol", "incomplete Cholesky", PcgPreconditioner::incomplete_cholesky),
        multigrid})
    t.add(std::move(row));
  return t;
}

NamedTable<PreconditionerRow>& table() {
  static NamedTable<PreconditionerRow> t = built_in();
  return t;
}

}  // namespace

const NamedTable<PreconditionerRow>& preconditioner_table() {
  return table();
}

void register_preconditioner(PreconditionerRow row) {
  table().add(std::move(row));
}

const PreconditionerRow& preconditioner_row(const std::string& name) {
  return table().at(name);
}

}  // namespace mcf
