#pragma once
// One flow (MCF, cMCF or heat flow) with any basis, solver and integrator: what `mcfbench flow`
// runs, with its result in memory instead of a folder (docs/library.md).

#include "mcfbench/export.h"
#include "mcfbench/mesh.h"
#include "mcfbench/types.h"

#include <functional>
#include <string>
#include <vector>

namespace mcfbench {

/// The state after a step, handed to a StepCallback.
struct Step {
  int step;               ///< 0 = the input, before the first step
  double t;               ///< step * dt
  VerticesView vertices;  ///< n x 3, in the input's vertex order; valid during the call only
};

/// Called after every step (and once before the first, with step 0) on the thread that called
/// flow(). Returns true to end the flow there: the result's status stays "ok" and its "stop" is
/// {"step": step, "reason": "stopped by the caller"}. An exception it throws ends the flow and
/// reaches flow()'s caller.
using StepCallback = std::function<bool(const Step&)>;

struct Frame {
  int step;
  Vertices vertices;  ///< n x 3
};

struct FlowResult {
  Vertices vertices;  ///< n x 3: the last step's positions, in the input's vertex order
  Faces faces;        ///< m x 3: the mesh's faces (as loaded: oriented, repaired)
  /// With "save-every" K > 0: the positions at step 0 and every K-th step, as `mcfbench flow`
  /// writes them to frame_NNNNN.ply; else empty.
  std::vector<Frame> frames;
  /// The result record as JSON text: what `mcfbench flow` writes to result.json (status, stop,
  /// config with every default filled in, environment, mesh, system, steps with each phase's
  /// seconds and the solver's residuals, memory; docs/design.md#the-result-file). Its
  /// "peak_memory_bytes" is this flow's peak (peak_memory_scope "cell") where Linux allows it.
  std::string result_json;
};

/// Runs a flow of the mesh the options' "mesh" names (a spec, as `--mesh` takes).
/// Inputs:
///   options   every option of `mcfbench flow` (docs/flow.md#flow) and max_memory; the flow
///             config's schema checks them
///   on_step   optional; see StepCallback
/// Output: FlowResult. A flow that turns singular (a solver failure, non-finite positions, a
/// collapsed area) is a result with status "singular", not an exception.
/// Throws InputError before anything runs on a bad option, mesh or combination;
/// std::runtime_error when the memory estimate does not fit the budget. One flow runs at a time
/// per process (its worker threads and BLAS threads are process-wide settings): a second call
/// from another thread waits.
MCFBENCH_API FlowResult flow(const Options& options, const StepCallback& on_step = {});

/// The same on a loaded mesh (Mesh::load, Mesh::from_arrays); the options must not name another
/// "mesh". Result positions are in the mesh's frame.
MCFBENCH_API FlowResult flow(const Mesh& mesh, const Options& options,
                             const StepCallback& on_step = {});

/// One option of the flow, as docs/flow.md's table lists it.
struct OptionInfo {
  std::string name;      ///< the flag without dashes, '-' as '_' ("normalize_area")
  std::string flag;      ///< "--normalize-area"
  std::string key;       ///< the config key ("normalize_area", "solver.cycles")
  std::string values;    ///< "4..10", "V | W", "true | false"
  std::string fallback;  ///< the default, as text
  std::string help;
  bool switch_only = false;  ///< a flag without a value on the command line: true or false here
};

/// Every option of flow(), in the order of `mcfbench flow --help`.
MCFBENCH_API std::vector<OptionInfo> flow_options();

}  // namespace mcfbench
