#pragma once
// A flow's peak resident memory, estimated from its sizes before anything is built, so that a flow
// that cannot fit is refused at once instead of growing until the kernel's OOM killer ends it (and,
// on a shared node, other jobs with it).
//
// The model is linear in the sizes that dominate: the input mesh's vertices (the mesh, its
// half-edge check, the hat basis's matrices, the tracked basis's per-vertex stencils and the
// per-triangle cubature data, which grows with the mesh) and the octree's function count (its
// matrices on the fixed pattern, the multigrid hierarchy, the normal-gradient term, a factor).
// The figures per vertex and per function were fitted to measured peaks (docs/benchmarks.md
// "Peak memory and set-up"); result.json records estimate and peak side by side, so the model can
// be checked on any run. Each basis and solver row carries its own model (config/memory_model.h):
// the estimate adds the basis's share and the solver's.

#include "config/config_values.h"
#include "config/memory_model.h"
#include "datasets/mesh.h"
#include "datasets/mesh_spec.h"

#include <nlohmann/json.hpp>

#include <string>

namespace mcf {

struct MemoryEstimate {
  double resident_bytes = 0;  ///< the process's resident memory when the estimate was made
  double mesh_bytes = 0;      ///< grows with the input mesh (per vertex)
  double basis_bytes = 0;     ///< grows with the octree's functions (0 for the hat basis)
  double solver_bytes = 0;    ///< a factor's fill or a dense matrix, beyond the iterative solvers
  double dimension = 0;       ///< unknowns: the vertices, or the octree functions estimated
  double vertices = 0;        ///< of the mesh the flow runs on
  bool lower_bound = false;   ///< the octree's size was unknown: its share is left out
  double total() const { return resident_bytes + mesh_bytes + basis_bytes + solver_bytes; }
  /// The estimate's figures, as result.json records them under "memory_estimate".
  nlohmann::json to_json() const;
  /// "12.4 GiB (hat basis, cholmod: 9.0e+07 vertices)" for messages.
  std::string describe(const FlowConfig& config) const;
};

/// "12.40 GiB": bytes for messages.
std::string format_gib(double bytes);

/// Sizes from a spec that has not been read or built: a generator's own estimate of its faces or
/// the "@faces=N" it is subdivided to (at least N faces). A closed surface has about half as many
/// vertices as faces. Zero for a file or model without "@faces" (its size is its own).
FlowSizes spec_sizes(const MeshSpecRequest& request);

/// Exact sizes of a loaded mesh for this config: vertex and face counts (four times the faces with
/// `octree.refine_input`), and for the octree basis its area over the side of the cube the basis
/// will choose. A cube the basis would refuse (`unit` on a mesh outside it) leaves the octree
/// unsized; the basis reports that error itself.
FlowSizes mesh_sizes(const FlowConfig& config, const TriangleMesh& mesh, bool analytic);

/// Peak resident memory of `config`'s flow on a mesh of `sizes`, `resident_bytes` being what the
/// process holds already.
MemoryEstimate estimate_flow_memory(const FlowConfig& config, const FlowSizes& sizes,
                                    double resident_bytes);

}  // namespace mcf
