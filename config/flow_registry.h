#pragma once
// The flow axis: one row per `flow` (mean-curvature flow and its variants). A flow is fixed by
// which of the operators of t = 0 it keeps: MCF re-assembles M and K every step, conformalized MCF
// (Kazhdan, Solomon & Ben-Chen 2012) keeps K_0, heat flow keeps both.

#include "config/named_table.h"

#include <string>

namespace mcf {

struct FlowRow {
  std::string name;
  std::string help;
  bool keeps_mass = false;       ///< M of t = 0 for every step
  bool keeps_stiffness = false;  ///< K of t = 0 for every step
  /// Non-empty: the flow needs a basis whose functions stay fixed, and this says why (the config
  /// error for a basis rebuilt every step).
  std::string fixed_basis_reason;
};

const NamedTable<FlowRow>& flow_table();
const FlowRow& flow_row(const std::string& name);

}  // namespace mcf
