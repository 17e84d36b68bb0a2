#include "harness/run_with_progress.h"

#include "harness/experiment_config.h"
#include "harness/progress.h"
#include "harness/runner.h"
#include "harness/stop_signals.h"
#include "solvers/petsc_runtime.h"

#include <chrono>
#include <cstdio>
#include <memory>
#include <stdexcept>

namespace mcf {
namespace {

/// The progress of a run on stderr: a step line inside a running cell, then the cell's own line.
class RunProgress {
 public:
  explicit RunProgress(double line_seconds) : line_seconds_(line_seconds) {}

  void step(const StepReport& r) {
    if (!steps_) {
      std::string what = "[";  // not "[" + std::string: GCC 12 warns on it (-Wrestrict, falsely)
      what += std::to_string(r.cell_number) + "/" + std::to_string(r.total) + "] cell " +
              std::to_string(r.plan->cell.index) + " step";
      steps_ = std::make_unique<Progress>(what, r.steps, line_seconds_);
    }
    steps_->update(r.step);
  }

  /// Ends a step line that a stop interrupted, so the message that follows starts a line.
  void stopped() {
    if (steps_) steps_->clear();
    steps_.reset();
  }

  /// Ends the step line (on a terminal the cell's own line replaces it), so the next cell's first
  /// step starts a new one.
  void cell(const CellReport& r) {
    if (steps_) steps_->clear();
    steps_.reset();
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    if (!r.skipped) {
      run_seconds_ += r.seconds;
      ++ran_;
    }
    const double left = ran_ > 0 ? run_seconds_ / ran_ * (r.total - r.done) : 0.0;
    std::fprintf(
        stderr, "[%d/%d] cell %d %s %-8s %7.2f s  elapsed %.1f s  left ~%.1f s  %s%s%s\n", r.done,
        r.total, r.plan->cell.index, r.plan->hash.c_str(), r.status.c_str(), r.seconds, elapsed,
        left, r.plan->cell.assignment.dump().c_str(),
        r.plan->cell.repetition ? (" rep " + std::to_string(r.plan->cell.repetition)).c_str() : "",
        r.error.empty() ? "" : ("\n    error: " + r.error).c_str());
  }

 private:
  double line_seconds_;
  const std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  double run_seconds_ = 0;
  int ran_ = 0;
  std::unique_ptr<Progress> steps_;
};

}  // namespace

int run_experiment_with_progress(const RunRequest& request) {
  // Every rank would run every cell into the same folder (docs/petsc.md, "Across MPI ranks").
  if (launched_ranks() > 1)
    throw std::runtime_error("run: started as one of " + std::to_string(launched_ranks()) +
                             " MPI ranks; a study runs in one process (use --shard to spread "
                             "its cells, or mpirun one `mcfbench flow` with --solver petsc)");
  const ExperimentConfig e = load_experiment_config(request.config, request.quick);
  const double line_seconds = progress_line_seconds();  // a bad value: nothing written
  RunOptions o;
  parse_shard(request.shard, o.shard_index, o.shard_count);
  o.out_dir =
      !request.out.empty() ? request.out : "results/" + e.name + (request.quick ? "-quick" : "");
  o.force = request.force;
  o.distances_only = request.distances_only;
  o.threads = request.threads;
  o.max_memory = request.max_memory;
  RunProgress progress(line_seconds);
  o.on_step = [&](const StepReport& r) { progress.step(r); };
  o.on_cell = [&](const CellReport& r) { progress.cell(r); };
  o.on_distance = [](int done, int total, int cell_index) {
    std::fprintf(stderr, "[distances %d/%d] cell %d\n", done, total, cell_index);
  };
  const StopSignals signals;
  o.stop_requested = &StopSignals::received;
  RunSummary s;
  try {
    s = run_experiment(e, o);
  } catch (const RunStopped& stop) {
    progress.stopped();
    const std::string plan = run_plan_path(o.out_dir, e, o.shard_index, o.shard_count);
    std::fprintf(stderr,
                 "mcfbench run: stopped by %s: %d of %d cells done (%d ran, %d skipped), the cell "
                 "that was running dropped; the plan %s and the finished cells are kept.\n"
                 "Rerun the same command to resume: finished cells are skipped.\n",
                 signal_name(stop.signal).c_str(), stop.done, stop.summary.in_shard,
                 stop.summary.ran, stop.summary.skipped, plan.c_str());
    return 128 + stop.signal;  // as a shell reports a process the signal ended
  }
  if (request.distances_only) {
    std::printf(
        "%s: %d cells, %d in shard %d/%d: %d with a result, %d without (not run: "
        "--distances-only), %d reference distances added; results in %s\n",
        e.name.c_str(), s.total, s.in_shard, o.shard_index, o.shard_count, s.skipped, s.not_run,
        s.distances, o.out_dir.c_str());
    return 0;
  }
  std::printf(
      "%s: %d cells, %d in shard %d/%d: %d ran%s, %d skipped, %d errors, %d reference "
      "distances; results in %s\n",
      e.name.c_str(), s.total, s.in_shard, o.shard_index, o.shard_count, s.ran,
      s.retried ? (" (" + std::to_string(s.retried) + " retried after an error)").c_str() : "",
      s.skipped, s.errors, s.distances, o.out_dir.c_str());
  return s.errors > 0 ? 1 : 0;
}

}  // namespace mcf
