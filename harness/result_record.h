#pragma once
// What the harness adds to a flow's result (flows/flow.h) before it becomes a result.json: the
// machine and build, the memory used, estimated and allowed, the time the run took and what
// competed with it for the cores, and the timing summary the studies compare. `mcfbench flow`
// (harness/flow_folder.h) and each cell of `mcfbench run` (harness/runner.h) add them through this
// one recorder, so both files carry the same keys; a cell adds its own (cell, study_config, frames,
// reference distances) on top (docs/design.md, "The result file").

#include "harness/contention.h"
#include "harness/memory_budget.h"

#include <nlohmann/json.hpp>

#include <chrono>

namespace mcf {

/// Started just before a flow runs (its mesh already loaded), completed once it has ended.
class ResultRecorder {
 public:
  /// Notes the time, the CPU counters and the stolen CPU time now. With `peak_of_this_flow`, the
  /// process's peak-memory mark is reset, so the recorded peak is this flow's (where Linux allows
  /// it); without, the whole process's peak is recorded (a process that runs one flow).
  explicit ResultRecorder(bool peak_of_this_flow);

  /// Inputs:
  ///   result           the flow's result (or a failed cell's error result)
  ///   threads          the config's worker threads (environment.threads)
  ///   memory_estimate  MemoryEstimate::to_json() of the flow; null where none was made (a cell
  ///                    whose mesh failed), and then no "memory_estimate" key
  ///   budget           the memory budget the flow was checked against
  /// Outputs (keys of `result`): environment, peak_memory_bytes, peak_memory_scope ("cell": this
  ///   flow's peak, "process": the process's), memory_estimate, memory_budget, run_seconds (since
  ///   the recorder started), steal_seconds (where the kernel reports it), contention, and timing
  ///   (harness/timing_summary.h; where the result has timed steps).
  void complete(nlohmann::json& result, int threads, const nlohmann::json& memory_estimate,
                const MemoryBudget& budget) const;

 private:
  std::chrono::steady_clock::time_point start_;
  bool peak_reset_ = false;
  double steal_before_ = -1;
  CpuCounters counters_before_;
};

}  // namespace mcf
