// flow(): what `mcfbench flow` does (harness/flow_folder.h) with the result kept in memory: the
// config through the flow config's schema, the memory check before and after the mesh is loaded,
// the flow itself (flows/flow.h) with the same observer hooks, and the same result record
// (harness/result_record.h).

#include "mcfbench/flow.h"

#include "api/detail.h"

#include "flows/flow.h"
#include "harness/flow_plan.h"
#include "harness/progress.h"
#include "harness/result_record.h"
#include "solvers/petsc_runtime.h"

#include <cstdio>
#include <optional>

namespace mcfbench {
namespace {

/// Refuses what needs more than one process: the library runs a flow where it is called.
void check_single_process(const mcf::FlowConfig& config, const std::string& source) {
  if (config.mpi_ranks != 1)
    throw InputError(source + ": mpi_ranks: " + std::to_string(config.mpi_ranks) +
                     " ranks asked for; a flow called from a program runs in its process (start "
                     "mpirun -n N mcfbench flow ... for a flow across ranks)");
  if (mcf::launched_ranks() > 1)
    throw InputError(source + ": this process is one of " + std::to_string(mcf::launched_ranks()) +
                     " MPI ranks; a flow called from a program runs in one process");
}

/// The plan's load check and run (harness/flow_plan.h) on `mesh`.
FlowResult run(const mcf::FlowPlan& plan, const mcf::MeshSource& mesh,
               const mcf::MemoryBudget& budget, const Options& options,
               const StepCallback& on_step) {
  const mcf::FlowConfig& config = plan.config;
  const mcf::MemoryEstimate memory = mcf::check_loaded_flow(plan, mesh, budget);
  const double line_seconds = options.progress ? mcf::progress_line_seconds() : 0;
  if (options.progress)
    for (const std::string& note : mesh.notes)
      std::fprintf(stderr, "mcfbench flow: %s: %s\n", config.mesh.c_str(), note.c_str());
  std::optional<mcf::Progress> progress;
  if (options.progress) progress.emplace("step", config.steps, line_seconds);

  FlowResult out;
  bool stop = false;
  mcf::FlowObserver observer;
  observer.on_step = [&](int step, double t, const mcf::Positions& V) {
    if (progress) progress->update(step);
    if (config.save_every > 0 && step % config.save_every == 0)
      out.frames.push_back({step, Vertices(V)});
    if (on_step) stop = on_step(Step{step, t, VerticesView(V.data(), V.rows(), 3)});
  };
  observer.stop = [&](int) { return stop; };
  // The peak of this flow, not of whatever the program did before it.
  const mcf::ResultRecorder recorder(/*peak_of_this_flow=*/true);
  mcf::FlowOutcome outcome = mcf::run_flow(config, mesh, observer);
  if (progress) progress->finish();
  recorder.complete(outcome.result, config.threads, memory.to_json(), budget);
  if (options.progress) {
    for (const auto& note : outcome.result.value("notes", nlohmann::json::array()))
      std::fprintf(stderr, "mcfbench flow: %s\n", note.get<std::string>().c_str());
    const auto& s = outcome.result["stop"];
    std::fprintf(stderr, "mcfbench flow: %s after %d steps (%s)\n",
                 outcome.result["status"].get<std::string>().c_str(), s["step"].get<int>(),
                 s["reason"].get<std::string>().c_str());
  }
  out.vertices = outcome.final_mesh.vertices;
  out.faces = outcome.final_mesh.faces;
  out.result_json = outcome.result.dump(1) + "\n";  // as result.json holds it
  return out;
}

/// The budget of options.max_memory; a malformed size names the option as the caller wrote it.
mcf::MemoryBudget budget_of(const Options& options) {
  if (!options.max_memory.empty() && options.max_memory != "none")
    mcf::parse_memory_size(options.max_memory, options.name + ": max_memory");
  return mcf::memory_budget(options.max_memory);
}

}  // namespace

FlowResult flow(const Options& options, const StepCallback& on_step) {
  const detail::RunScope one_at_a_time(options.name);
  mcf::FlowPlan plan;
  mcf::MemoryBudget budget;
  mcf::MeshSource mesh;
  detail::translated([&] {
    plan = mcf::prepare_flow(detail::flow_config(options));
    check_single_process(plan.config, options.name);
    budget = budget_of(options);
    // Before a generated mesh is built (a spec's size is known from the spec), as the command
    // line checks it.
    mcf::estimate_flow(plan, budget);
    mesh = mcf::load_flow_mesh(plan);
  });
  return detail::translated([&] { return run(plan, mesh, budget, options, on_step); });
}

FlowResult flow(const Mesh& mesh, const Options& options, const StepCallback& on_step) {
  const detail::RunScope one_at_a_time(options.name);
  // The mesh is loaded already: the plan's spec is not parsed (a mesh of arrays has a name only).
  mcf::FlowPlan plan;
  mcf::MemoryBudget budget;
  detail::translated([&] {
    plan.config = detail::flow_config(options, mesh.spec());
    plan.what = plan.config.mesh;
    const mcf::FlowConfig& config = plan.config;
    check_single_process(config, options.name);
    budget = budget_of(options);
    const mcf::MeshSource& source = mesh.impl().source;
    // A mesh loaded with other options than this flow's may hold zero-area faces its basis
    // cannot take.
    if (source.report.degenerate_faces > 0 &&
        mcf::mesh_load_options(config).degenerate != mcf::DegenerateFaces::keep)
      throw InputError(options.name + ": basis: the " + config.basis +
                       " basis needs every face's cotangents, and " + mesh.spec() + " has " +
                       std::to_string(source.report.degenerate_faces) +
                       " zero-area faces (load it with the flow's options, or with "
                       "repair_degenerate)");
  });
  return detail::translated(
      [&] { return run(plan, mesh.impl().source, budget, options, on_step); });
}

}  // namespace mcfbench
