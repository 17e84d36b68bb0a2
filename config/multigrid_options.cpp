#include "config/multigrid_options.h"

namespace mcf {

MultigridOptions multigrid_options(const SolverConfig& c) {
  MultigridOptions o;
  o.cycle = c.cycle == "V" ? MultigridCycle::V : MultigridCycle::W;
  o.cycles = c.cycles;
  o.pre_smooth = o.post_smooth = c.smooth;
  o.tolerance = c.tolerance;
  o.galerkin_by_term = c.galerkin_by_term;
  o.mixed_precision = c.precision == "mixed";
  o.galerkin_refresh = c.galerkin_refresh;
  return o;
}

}  // namespace mcf
