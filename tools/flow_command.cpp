// `mcfbench flow`: one flow, written to OUT/result.json and OUT/final.ply (+ frames).
// Frames and final.ply are staged in OUT/.mcfbench-staging while the flow runs and moved into OUT
// only once it has finished, result.json last: an interrupted or failed run into an existing OUT
// leaves the previous run's files as they were, never its result beside the new run's frames.

#include "bench/environment.h"
#include "core/atomic_file.h"
#include "datasets/mesh_io.h"
#include "datasets/mesh_spec.h"
#include "flows/config_reader.h"
#include "flows/flow.h"
#include "flows/flow_config.h"
#include "flows/integrator.h"
#include "tools/commands.h"
#include "tools/progress.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>

namespace mcf {
namespace {

/// Hidden (reports' globs and `collect` skip it), and removed by the next flow into OUT when a
/// killed run left it.
constexpr const char* kStagingFolder = ".mcfbench-staging";

bool is_frame_file(const std::filesystem::path& p) {
  const std::string stem = p.stem().string();
  return p.extension() == ".ply" && stem.rfind("frame_", 0) == 0 && stem.size() > 6 &&
         stem.find_first_not_of("0123456789", 6) == std::string::npos;
}

struct FlowArgs {
  std::string config_file, out;
  // Every flag maps to one key of the flow config; only flags given on the command line are
  // set, so --config FILE supplies the rest.
  std::string mesh, flow, basis, mass, tracking, cube, solver, preconditioner, cycle, integrator;
  int depth = 0, cubature = 0, max_iterations = 0, cycles = 0, smooth = 0, steps = 0, threads = 0,
      save_every = 0;
  double dt = 0, tolerance = 0;
  bool refine_input = false, normalize_area = false, frozen = false;
};

}  // namespace

void add_flow_command(CLI::App& app, std::function<int()>& run) {
  auto args = std::make_shared<FlowArgs>();
  CLI::App* cmd = app.add_subcommand(
      "flow", "Run one flow and write OUT/result.json, OUT/final.ply (and frames).");
  cmd->footer("Mesh specs:\n" + mesh_spec_help() +
              "\nExample:\n  mcfbench flow --mesh sphere:vertices=2000 --flow mcf --basis hat "
              "--solver cholmod "
              "--dt 1e-3 --steps 20 --out out/sphere\n");
  cmd->add_option("--config", args->config_file,
                  "JSON flow config (same keys as result.json's \"config\"); flags override it");
  cmd->add_option("--mesh", args->mesh,
                  "Mesh spec: generator, cgal:MODEL[@faces=N] or a file path");
  cmd->add_option("--flow", args->flow,
                  "mcf | cmcf (stiffness of t=0 kept) | heat (both operators of t=0)");
  cmd->add_option("--basis", args->basis, "hat (P1, cotangent) | octree (trilinear B-splines)");
  cmd->add_option("--mass", args->mass, "Hat basis mass matrix: consistent (default) | lumped");
  cmd->add_option(
      "--tracking", args->tracking,
      "Octree: tracked (default; built once, metric re-integrated) | rebuilt (every step)");
  cmd->add_option("--depth", args->depth, "Octree depth (finest level), 4..10 (default 8)");
  cmd->add_option("--cubature", args->cubature,
                  "Octree cubature rule per split triangle: 1 | 3 (default) | 6");
  cmd->add_option(
      "--cube", args->cube,
      "Octree bounding cube: auto (default: unit cube if the mesh fits) | unit | tight");
  cmd->add_flag("--refine-input", args->refine_input,
                "Octree: split the input mesh 1-to-4 once first");
  cmd->add_option("--solver", args->solver,
                  "cholmod (default) | pcg | multigrid | dense (LLT of the dense matrix: a "
                  "reference for small meshes)");
  cmd->add_option(
      "--tolerance", args->tolerance,
      "Relative residual to stop at (PCG default 1e-10; multigrid default 0 = run --cycles)");
  cmd->add_option("--max-iterations", args->max_iterations, "PCG iteration cap (default 1000)");
  cmd->add_option("--preconditioner", args->preconditioner,
                  "PCG: none | jacobi (default) | ichol | multigrid");
  cmd->add_option("--cycle", args->cycle, "Multigrid cycle: V | W (default)");
  cmd->add_option("--cycles", args->cycles, "Multigrid cycles per solve (default 1)");
  cmd->add_option("--smooth", args->smooth,
                  "Gauss-Seidel sweeps before and after each coarse correction (default 5)");
  cmd->add_option(
      "--integrator", args->integrator,
      "explicit-euler | semi-implicit (default) | crank-nicolson | bdf2 | taylor2 | neumann2");
  cmd->add_flag("--frozen", args->frozen,
                "CN/BDF2: evaluate operators at X_n instead of the extrapolated X* (first order)");
  cmd->add_option("--dt", args->dt, "Time step (default 1e-3)");
  cmd->add_option("--steps", args->steps, "Number of steps (default 10)");
  cmd->add_flag("--normalize-area", args->normalize_area,
                "Unit total area, centroid at the origin, before and after every step");
  cmd->add_option("--threads", args->threads, "Worker threads (0 = all cores, default)");
  cmd->add_option("--save-every", args->save_every,
                  "Write OUT/frame_NNNNN.ply every K steps (0 = never)");
  cmd->add_option("--out", args->out, "Output folder")->required();

  run = nullptr;
  cmd->callback([cmd, args, &run] {
    run = [cmd, args]() -> int {
      // Assemble one JSON config from --config and the flags given, then validate it in one
      // place (flow_config_from_json) so the command line and experiment configs agree.
      nlohmann::json j = nlohmann::json::object();
      std::string source = "command line";
      if (!args->config_file.empty()) {
        j = read_config_file(args->config_file);
        source = args->config_file + " (+ command line)";
      }
      auto given = [&](const char* flag) { return cmd->count(flag) > 0; };
      auto set = [&](const char* flag, const std::string& path, auto value) {
        if (!given(flag)) return;
        nlohmann::json* node = &j;
        std::string p = path;
        for (auto dot = p.find('.'); dot != std::string::npos; dot = p.find('.')) {
          node = &(*node)[p.substr(0, dot)];
          p = p.substr(dot + 1);
        }
        (*node)[p] = value;
      };
      set("--mesh", "mesh", args->mesh);
      set("--flow", "flow", args->flow);
      set("--basis", "basis", args->basis);
      set("--mass", "mass", args->mass);
      set("--tracking", "octree.tracking", args->tracking);
      set("--depth", "octree.depth", args->depth);
      set("--cubature", "octree.cubature", args->cubature);
      set("--cube", "octree.cube", args->cube);
      set("--refine-input", "octree.refine_input", args->refine_input);
      set("--solver", "solver.name", args->solver);
      set("--tolerance", "solver.tolerance", args->tolerance);
      set("--max-iterations", "solver.max_iterations", args->max_iterations);
      set("--preconditioner", "solver.preconditioner", args->preconditioner);
      set("--cycle", "solver.cycle", args->cycle);
      set("--cycles", "solver.cycles", args->cycles);
      set("--smooth", "solver.smooth", args->smooth);
      set("--integrator", "integrator", args->integrator);
      if (given("--frozen")) j["extrapolate"] = !args->frozen;
      set("--dt", "dt", args->dt);
      set("--steps", "steps", args->steps);
      set("--normalize-area", "normalize_area", args->normalize_area);
      set("--threads", "threads", args->threads);
      set("--save-every", "save_every", args->save_every);

      const FlowConfig config = flow_config_from_json(j, source);
      const MeshSource mesh =
          load_mesh_spec(config.mesh);  // throws naming the file: nothing written yet
      const double line_seconds = progress_line_seconds();  // a bad MCFBENCH_PROGRESS_SECONDS too

      namespace fs = std::filesystem;
      const fs::path out(args->out);
      // A folder this run creates is removed again if the flow throws (a set-up error such as
      // `--cube unit` on a mesh outside the unit cube): no empty folder or partial frames left.
      // In a folder that exists, only the staging folder is this run's until the flow is done.
      const bool created = !fs::exists(out);
      const fs::path staging = out / kStagingFolder;
      fs::remove_all(staging);  // a killed run's
      fs::create_directories(staging);
      std::set<std::string> frames;
      FlowOutcome outcome;
      const double steal_before = cpu_steal_seconds();
      try {
        Progress progress("step", config.steps, line_seconds);
        FlowObserver observer;
        observer.on_step = [&](int step, double, const Positions& V) {
          progress.update(step);
          if (config.save_every > 0 && step % config.save_every == 0) {
            char name[32];
            std::snprintf(name, sizeof name, "frame_%05d.ply", step);
            write_mesh((staging / name).string(), TriangleMesh{V, mesh.mesh.faces}, true,
                       FaceCheck::trusted);
            frames.insert(name);
          }
        };
        outcome = run_flow(config, mesh, observer);
        progress.finish();
      } catch (...) {
        std::error_code ec;
        fs::remove_all(created ? out : staging, ec);
        throw;
      }
      outcome.result["environment"] = environment_json(config.threads);
      outcome.result["peak_memory_bytes"] = peak_memory_bytes();
      if (const double steal = cpu_steal_seconds_since(steal_before); steal >= 0)
        outcome.result["steal_seconds"] = steal;
      write_mesh((staging / "final.ply").string(), outcome.final_mesh, true, FaceCheck::trusted);
      // Publish. The earlier run's result goes first, so from here until the new one is in place
      // OUT holds no result at all rather than one beside frames that are not its own; then the
      // earlier run's frames that this run does not replace, then this run's files move in
      // (rename: each appears whole), and result.json comes last, atomically.
      fs::remove(out / "result.json");
      for (const auto& entry : fs::directory_iterator(out))
        if (entry.is_regular_file() && is_frame_file(entry.path()) &&
            !frames.count(entry.path().filename().string()))
          fs::remove(entry.path());
      for (const std::string& name : frames) fs::rename(staging / name, out / name);
      fs::rename(staging / "final.ply", out / "final.ply");
      write_file_atomic((out / "result.json").string(), outcome.result.dump(1) + "\n");
      fs::remove_all(staging);
      const auto& stop = outcome.result["stop"];
      std::fprintf(stderr, "mcfbench flow: %s after %d steps (%s); wrote %s\n",
                   outcome.result["status"].get<std::string>().c_str(), stop["step"].get<int>(),
                   stop["reason"].get<std::string>().c_str(), (out / "result.json").c_str());
      return 0;
    };
  });
}

}  // namespace mcf
