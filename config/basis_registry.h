#pragma once
// The basis axis: one row per finite-element basis `basis` selects (docs/extending.md "Adding a
// basis"), and the octree basis's own sub-axis, `octree.tracking`. The flow, the config checks
// and the memory estimate read a basis's meaning from its row.

#include "bases/basis.h"
#include "bases/octree_basis.h"
#include "config/config_values.h"
#include "config/memory_model.h"
#include "config/named_table.h"
#include "config/option_spec.h"
#include "datasets/mesh.h"

#include <functional>
#include <memory>
#include <optional>
#include <string>

namespace mcf {

/// The octree's normal-gradient weight under a direct solver: the paper's system made definite
/// where faces parallel to the grid planes leave it singular, its surface unchanged to about 1e-5
/// relative.
inline constexpr double kDefiniteStabilizationWeight = 1e-6;

struct BasisRow {
  std::string name;
  std::string help;
  /// Builds the basis of `config` on `mesh`; `hierarchy`: the solver needs the basis's geometric
  /// hierarchy (needs_hierarchy, config/solver_registry.h). `analytic`: a generated shape.
  std::function<std::unique_ptr<Basis>(const FlowConfig& config, const TriangleMesh& mesh,
                                       bool analytic, bool hierarchy)>
      make;
  /// Its share of the flow's memory and its unknowns for a mesh of `sizes`. Required.
  std::function<BasisMemory(const FlowConfig&, const FlowSizes&)> memory;
  /// Its options, keyed from the top ("octree.depth"). Every config reads them and result.json
  /// records them for every basis (the configs of earlier results have them).
  std::vector<OptionSpec> options{};
  /// Its system matrix as the solvers' memory models read it (dimension left 0).
  SystemFigures system{};
  /// Optional: fills what the basis's size depends on beyond the mesh's counts (the octree's
  /// cube) into `sizes`.
  std::function<void(const FlowConfig&, const TriangleMesh&, bool analytic, FlowSizes& sizes)>
      size{};
  /// Optional: whether its functions stay the same through the flow (default: they do). cMCF,
  /// heat flow and two-step integrators need them to.
  std::function<bool(const FlowConfig&)> fixed_functions{};
  /// Optional: the weight c of the normal-gradient stabilization its system carries; none: the
  /// paper's system (steps/stabilization.h).
  std::function<std::optional<double>(const FlowConfig&)> stabilization{};
  /// Optional: what the memory message says after "<name> basis" (" depth 8").
  std::function<std::string(const FlowConfig&)> describe{};
  bool takes_mass = false;  ///< reads `mass` (consistent | lumped)
  /// Integrates over the surface by cubature, so zero-area faces may stay (they add nothing);
  /// otherwise it needs every face's cotangents and refuses them.
  bool keeps_degenerate_faces = false;
};

/// A variant of the octree basis (`octree.tracking`).
struct TrackingRow {
  std::string name;
  std::string help;
  std::function<std::unique_ptr<Basis>(const TriangleMesh&, const OctreeOptions&)> make;
  double bytes_per_vertex = 0;    ///< memory fit: mesh, stencils or clipped pieces
  double bytes_per_function = 0;  ///< memory fit: matrices, hierarchy, vectors
  bool fixed_functions = true;    ///< false: rebuilt every step
};

const NamedTable<BasisRow>& basis_table();
/// Throws std::logic_error for a row without a factory or a memory model, or a name taken.
void register_basis(BasisRow row);
const BasisRow& basis_row(const std::string& name);

const NamedTable<TrackingRow>& tracking_table();
const TrackingRow& tracking_row(const std::string& name);

/// The octree basis's options for a config; `analytic` shapes get the tight cube under "auto".
OctreeOptions octree_options(const OctreeConfig& c, bool analytic);

/// Fills in `octree.stabilization_weight` left to the solver (< 0) once the whole config is read,
/// so that result.json records the weight that ran where the system carries the term: 0.5 under an
/// iterative solver, kDefiniteStabilizationWeight under a direct one; else 0.5 (inert: the value
/// such configs recorded before, so their config keys stay). A weight set stays.
void resolve_stabilization_weight(FlowConfig& c);

}  // namespace mcf
