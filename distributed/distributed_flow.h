#pragma once
// One flow divided across MPI ranks (docs/petsc.md, "Across MPI ranks"): rank 0 reads the mesh
// and scatters it (distributed/rank_mesh.h), each rank assembles and solves its own rows
// (distributed/rank_system.h), and the step — any integrator of steps/integrator.h, MCF, cMCF or
// heat flow, lumped or consistent mass, a fixed boundary, unit-area normalisation — runs on the
// owned rows, the ghost ring exchanged whenever the operators or a product need it. Every sum
// over the surface (area, moments, step difference, radial error) is an ordered sum
// (distributed/comm.h): a rerun on the same ranks gives the same bits, other rank counts differ
// by rounding only. Frames and the final mesh are gathered on rank 0 in the input's vertex order.
//
// The hat basis only: the octree bases refuse more than one rank (their functions are grid
// cells, and a partition by cells is a different design), as do the solvers that do not run
// across ranks.

#include "config/flow_config.h"
#include "datasets/mesh_spec.h"
#include "flows/flow.h"

#include <functional>
#include <string>

namespace mcf::dist {

/// Why `config` cannot run divided across `ranks` ranks, or "" if it can (the hat basis with
/// petsc, multigrid, or pcg with the multigrid preconditioner; no refine_input).
std::string distributed_refusal(const FlowConfig& config, int ranks);

struct DistributedObserver {
  /// Rank 0: whether step `step`'s vertices are wanted (a frame); only then are they gathered.
  std::function<bool(int step)> wants_vertices;
  /// Rank 0, after each step (step 0: the input): the vertices in the input's order when
  /// wants_vertices said so, else nullptr.
  std::function<void(int step, double t, const Positions* vertices)> on_step;
};

/// Collective: every rank calls it; `source` is the loaded mesh on rank 0 and nullptr on the
/// others. Returns, on rank 0, the result record (as run_flow's, with "distribution" added: the
/// ranks, the partitioner, per rank the owned and ghost vertices, the local triangles and the
/// peak memory, per phase the slowest rank's seconds and the imbalance) and the final mesh; an
/// empty outcome on the other ranks. A stop rule ends the flow on every rank at the same step.
FlowOutcome run_distributed_flow(const FlowConfig& config, const MeshSource* source,
                                 const DistributedObserver& observer = {});

}  // namespace mcf::dist
