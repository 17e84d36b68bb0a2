#pragma once
// Runs one flow (MCF, cMCF or heat) with any basis, solver and integrator, and records what
// result.json needs. Stops cleanly when the flow turns singular (solver failure, non-finite
// positions, collapsed area) and records the step and the reason.

#include "config/flow_config.h"
#include "datasets/mesh_spec.h"
#include "flows/surface_moments.h"

#include <nlohmann/json.hpp>

#include <functional>

namespace mcf {

struct FlowObserver {
  /// After each step with the new vertex positions (frames, progress). Step 0 = the input.
  std::function<void(int step, double t, const Positions& vertices)> on_step;
  /// Asked after on_step (step 0 too): true ends the flow there. That is not a failure: the
  /// status stays "ok" and result["stop"] is {"step": step, "reason": "stopped by the caller"}.
  std::function<bool(int step)> stop;
};

struct FlowOutcome {
  nlohmann::json result;    ///< status, stop, config, mesh, system, steps (no environment)
  TriangleMesh final_mesh;  ///< vertex order of the input kept
};

FlowOutcome run_flow(const FlowConfig& config, const MeshSource& source,
                     const FlowObserver& observer = {});

/// result.json's "mesh": the spec and the loaded mesh's validation report.
nlohmann::json mesh_json(const MeshSource& source);

/// Scales the mesh to unit area about its area-weighted centroid, moved to the origin:
/// returns (scale, centroid) so the same map can be applied to coefficients (B-splines
/// reproduce affine maps, so x ↦ s (x - c) maps the surface the same way).
struct Normalization {
  double scale = 1.0;
  Eigen::RowVector3d centroid = Eigen::RowVector3d::Zero();
};
Normalization unit_area_normalization(const Positions& V, const Triangles& F);
/// The same from the surface's moments (flows/surface_moments.h), when they are at hand.
Normalization unit_area_normalization(const SurfaceMoments& moments);

}  // namespace mcf
