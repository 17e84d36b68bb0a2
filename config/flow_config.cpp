#include "config/flow_config.h"

#include "config/basis_registry.h"
#include "config/config_reader.h"
#include "config/config_schema.h"
#include "config/flow_registry.h"
#include "config/solver_registry.h"
#include "steps/integrator.h"

#include <optional>

namespace mcf {
namespace {

/// Set to a value other than its default where no component of `c` reads it.
bool inapplicable(const OptionSpec& o, const FlowConfig& c) {
  return o.refused_elsewhere && !o.selected(c) && o.get(c) != o.fallback;
}

}  // namespace

FlowConfig flow_config_from_json(const nlohmann::json& j, const std::string& source) {
  FlowConfig c = flow_config_from_json_unchecked(j, source);
  validate_flow_config(c, source);
  return c;
}

FlowConfig flow_config_from_json_unchecked(const nlohmann::json& j, const std::string& source) {
  ConfigReader top(j, source);
  FlowConfig c;
  // One option after the other in the schema's order; an object's reader is finished (its
  // unknown keys reported) when its last option has been read.
  std::string object;
  std::optional<ConfigReader> child;
  for (const OptionSpec& o : flow_config_schema()) {
    const std::string parent = split_key(o.key).first;
    if (parent != object) {
      if (child) child->finish();
      child.reset();
      object = parent;
      if (!parent.empty()) child.emplace(top.child(parent));
    }
    read_option(parent.empty() ? top : *child, o, c);
  }
  if (child) child->finish();
  top.finish();
  if (c.solver.tolerance < 0) c.solver.tolerance = solver_row(c.solver.name).default_tolerance;
  resolve_stabilization_weight(c);
  return c;
}

std::vector<std::string> inapplicable_keys(const FlowConfig& c) {
  std::vector<std::string> keys;
  for (const OptionSpec& o : flow_config_schema())
    if (inapplicable(o, c)) keys.push_back(o.key);
  return keys;
}

nlohmann::json to_json(const FlowConfig& c) {
  nlohmann::json j = nlohmann::json::object();
  for (const OptionSpec& o : flow_config_schema()) {
    // when_set and when_selected: a key present where it changes nothing would change the config
    // key of every cell (harness/cell_hash.h), and `compare` would find no cell of an earlier run
    // to compare with.
    if (o.recorded == Recorded::when_set && o.get(c) == o.fallback) continue;
    if (o.recorded == Recorded::when_selected && !o.selected(c)) continue;
    const auto [parent, leaf] = split_key(o.key);
    (parent.empty() ? j : j[parent])[leaf] = o.get(c);
  }
  return j;
}

void validate_flow_config(const FlowConfig& c, const std::string& source) {
  auto fail = [&](const std::string& key, const std::string& what) {
    throw ConfigError(source + ": " + key + ": " + what);
  };
  const BasisRow& basis = basis_row(c.basis);
  const bool fixed = !basis.fixed_functions || basis.fixed_functions(c);
  // Options no solver reads would be recorded as if they had shaped the run (or dropped
  // without a word).
  std::string in_use = "\"" + c.solver.name + "\"";
  if (solver_row(c.solver.name).uses_preconditioner)
    in_use += " with preconditioner \"" + preconditioner_name(c.solver) + "\"";
  for (const OptionSpec& o : flow_config_schema())
    if (inapplicable(o, c))
      fail(o.key, (o.type == OptionType::string ? "\"" + o.get(c).get<std::string>() + "\" " : "") +
                      "applies to " + o.owner_text + " only, " +
                      (o.in_use ? o.in_use(c) : "the solver is " + in_use));
  // Accepting it would record a lumped mass the flow never used (and duplicate an axis's cells).
  if (!basis.takes_mass && c.mass != "consistent")
    fail("mass", "\"" + c.mass +
                     "\" applies to the hat basis only; the octree basis integrates its "
                     "consistent mass matrix by cubature");
  if (!fixed && !flow_row(c.flow).fixed_basis_reason.empty())
    fail("flow", flow_row(c.flow).fixed_basis_reason);
  if (!fixed && make_integrator(c.integrator, c.extrapolate)->uses_previous())
    fail("integrator",
         "two-step schemes need coefficients in one fixed basis; the rebuilt octree "
         "changes its functions every step");
}

void validate_flow_mesh(const FlowConfig& c, const MeshReport& mesh, const std::string& source) {
  // An open surface's boundary is held where it is (docs/design.md "Conventions"; the cMCF paper
  // flows an open surface with its boundary fixed), while unit-area normalisation rescales and
  // recentres the whole surface every step: the held boundary would move with it (a loop grew by
  // 24% in 8 steps of cMCF on the mannequin). The two contradict each other, so refuse.
  if (c.normalize_area && mesh.boundary_loops > 0)
    throw ConfigError(
        source + ": normalize_area: the mesh has " + std::to_string(mesh.boundary_loops) +
        " boundary loop(s), held fixed through the flow, which rescaling to unit area every "
        "step would move; run an open surface without normalize_area (leave out "
        "--normalize-area, or set \"normalize_area\": false): its boundary stays where it is and "
        "a time step then means what it does at the mesh's own size (files are scaled into the "
        "unit cube), or close its holes first to flow it at unit area");
}

MeshLoadOptions mesh_load_options(const FlowConfig& c) {
  MeshLoadOptions o;
  if (c.repair_degenerate) {
    o.degenerate = DegenerateFaces::repair;
  } else if (basis_row(c.basis).keeps_degenerate_faces) {
    // The octree basis integrates over the surface by cubature on clipped pieces, and a
    // zero-area face leaves no piece: it changes nothing there.
    o.degenerate = DegenerateFaces::keep;
  } else {
    o.degenerate_hint =
        ": the hat basis needs every face's cotangents, which a zero-area face lacks; "
        "--repair-degenerate (config key repair_degenerate) removes zero-area faces, or "
        "--basis octree takes them as they are";
  }
  return o;
}

}  // namespace mcf
