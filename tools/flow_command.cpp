// `mcfbench flow`: the flags of one flow, written to OUT/result.json and OUT/final.ply (+ frames)
// by bench/flow_folder.h. Every flag maps to one key of the flow config.

#include "bench/flow_folder.h"
#include "datasets/mesh_spec.h"
#include "tools/commands.h"

#include <memory>

namespace mcf {
namespace {

struct FlowArgs {
  std::string config_file, out, max_memory, blas_threads;
  // Every flag maps to one key of the flow config; only flags given on the command line are
  // set, so --config FILE supplies the rest.
  std::string mesh, flow, basis, mass, tracking, cube, stabilization, solver, preconditioner, cycle,
      integrator, petsc_options;
  int depth = 0, cubature = 0, max_iterations = 0, cycles = 0, smooth = 0, steps = 0, threads = 0,
      save_every = 0;
  double dt = 0, tolerance = 0, stabilization_weight = 0, stall_ratio = 0, fallback_tolerance = 0;
  bool refine_input = false, normalize_area = false, frozen = false, repair_degenerate = false;
};

void add_flow_options(CLI::App& cmd, FlowArgs& args) {
  cmd.add_option("--config", args.config_file,
                 "JSON flow config (same keys as result.json's \"config\"); flags override it");
  cmd.add_option("--mesh", args.mesh, "Mesh spec: generator, cgal:MODEL[@faces=N] or a file path");
  cmd.add_option("--flow", args.flow,
                 "mcf | cmcf (stiffness of t=0 kept) | heat (both operators of t=0)");
  cmd.add_option("--basis", args.basis, "hat (P1, cotangent) | octree (trilinear B-splines)");
  cmd.add_option("--mass", args.mass, "Hat basis mass matrix: consistent (default) | lumped");
  cmd.add_option(
      "--tracking", args.tracking,
      "Octree: tracked (default; built once, metric re-integrated) | rebuilt (every step)");
  cmd.add_option("--depth", args.depth, "Octree depth (finest level), 4..10 (default 8)");
  cmd.add_option("--cubature", args.cubature,
                 "Octree cubature rule per split triangle: 1 | 3 (default) | 6");
  cmd.add_option("--cube", args.cube,
                 "Octree bounding cube: auto (default: unit cube if the mesh fits) | unit | tight");
  cmd.add_flag("--refine-input", args.refine_input,
               "Split the input mesh 1-to-4 once first (octree and hat basis); only its vertices "
               "are output");
  cmd.add_option("--stabilization", args.stabilization,
                 "Octree: none (the paper's system) | normal-gradient (solve each step's "
                 "increment with the band's normal-gradient term added)");
  cmd.add_option("--stabilization-weight", args.stabilization_weight,
                 "Octree: the normal-gradient term's diagonal over the system's (default 0.5)");
  cmd.add_option("--solver", args.solver,
                 "cholmod (default) | pcg | multigrid | petsc (PETSc's KSP, default CG + GAMG) | "
                 "dense (LLT of the dense matrix: a reference for small meshes)");
  cmd.add_option(
      "--tolerance", args.tolerance,
      "Relative residual to stop at (PCG default 1e-10; multigrid default 0 = run --cycles)");
  cmd.add_option("--max-iterations", args.max_iterations,
                 "PCG iteration cap (default 1000; petsc: 3000)");
  cmd.add_option("--petsc-options", args.petsc_options,
                 "petsc: PETSc options over the defaults, e.g. \"-pc_type hypre -pc_hypre_type "
                 "boomeramg\" (docs/petsc.md)");
  cmd.add_option("--preconditioner", args.preconditioner,
                 "PCG: none | jacobi (default) | ichol | multigrid");
  cmd.add_option("--cycle", args.cycle, "Multigrid cycle: V | W (default)");
  cmd.add_option("--cycles", args.cycles, "Multigrid cycles per solve (default 1)");
  cmd.add_option("--smooth", args.smooth,
                 "Gauss-Seidel sweeps before and after each coarse correction (default 5)");
  cmd.add_option("--stall-ratio", args.stall_ratio,
                 "Multigrid: where the cycles reduce the residual by less than this per cycle, CG "
                 "preconditioned by the cycle takes over until they have reached what this ratio "
                 "promises (default 0.2; 0 = never)");
  cmd.add_option(
      "--fallback-tolerance", args.fallback_tolerance,
      "Multigrid: the fallback CG never stops below this relative residual (default 1e-10)");
  cmd.add_option(
      "--integrator", args.integrator,
      "explicit-euler | semi-implicit (default) | crank-nicolson | bdf2 | taylor2 | neumann2");
  cmd.add_flag("--frozen", args.frozen,
               "CN/BDF2: evaluate operators at X_n instead of the extrapolated X* (first order)");
  cmd.add_option("--dt", args.dt, "Time step (default 1e-3)");
  cmd.add_option("--steps", args.steps, "Number of steps (default 10)");
  cmd.add_flag("--normalize-area", args.normalize_area,
               "Unit total area, centroid at the origin, before and after every step");
  cmd.add_option("--threads", args.threads, "Worker threads (0 = all cores, default)");
  cmd.add_option("--blas-threads", args.blas_threads,
                 "OpenBLAS threads under CHOLMOD: auto (default: one below 20000 unknowns, else "
                 "up to 4) | N (at most --threads)");
  cmd.add_option("--save-every", args.save_every,
                 "Write OUT/frame_NNNNN.ply every K steps (0 = never)");
  cmd.add_option("--max-memory", args.max_memory,
                 "Refuse a flow whose estimated peak memory exceeds SIZE (8G, 512M; none: no "
                 "check; default: the memory available now)");
  cmd.add_flag("--repair-degenerate", args.repair_degenerate,
               "Collapse the mesh's zero-area faces first (the hat basis refuses them; the octree "
               "basis takes them as they are)");
  cmd.add_option("--out", args.out, "Output folder")->required();
}

/// The settings of the flags given on the command line, in the flow config's keys; --config FILE
/// supplies the rest.
FlowRequest flow_request(const CLI::App& cmd, const FlowArgs& args) {
  FlowRequest r;
  r.config_file = args.config_file;
  r.out = args.out;
  r.max_memory = args.max_memory;
  auto set = [&](const char* flag, const char* key, const nlohmann::json& value) {
    if (cmd.count(flag) > 0) r.settings.emplace_back(key, value);
  };
  set("--mesh", "mesh", args.mesh);
  set("--flow", "flow", args.flow);
  set("--basis", "basis", args.basis);
  set("--mass", "mass", args.mass);
  set("--tracking", "octree.tracking", args.tracking);
  set("--depth", "octree.depth", args.depth);
  set("--cubature", "octree.cubature", args.cubature);
  set("--cube", "octree.cube", args.cube);
  set("--stabilization", "octree.stabilization", args.stabilization);
  set("--stabilization-weight", "octree.stabilization_weight", args.stabilization_weight);
  set("--refine-input", "octree.refine_input", args.refine_input);
  set("--solver", "solver.name", args.solver);
  set("--tolerance", "solver.tolerance", args.tolerance);
  set("--max-iterations", "solver.max_iterations", args.max_iterations);
  set("--preconditioner", "solver.preconditioner", args.preconditioner);
  set("--petsc-options", "solver.petsc_options", args.petsc_options);
  set("--cycle", "solver.cycle", args.cycle);
  set("--cycles", "solver.cycles", args.cycles);
  set("--smooth", "solver.smooth", args.smooth);
  set("--stall-ratio", "solver.stall_ratio", args.stall_ratio);
  set("--fallback-tolerance", "solver.fallback_tolerance", args.fallback_tolerance);
  set("--integrator", "integrator", args.integrator);
  set("--frozen", "extrapolate", !args.frozen);
  set("--dt", "dt", args.dt);
  set("--steps", "steps", args.steps);
  set("--normalize-area", "normalize_area", args.normalize_area);
  set("--threads", "threads", args.threads);
  if (cmd.count("--blas-threads") > 0) {
    int n = 0;
    if (args.blas_threads != "auto") {
      std::size_t used = 0;
      try {
        n = std::stoi(args.blas_threads, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != args.blas_threads.size() || n < 1 || n > 4096)
        throw CLI::ValidationError("--blas-threads", "expected auto or a count 1..4096, got \"" +
                                                         args.blas_threads + "\"");
    }
    r.settings.emplace_back("blas_threads", n);
  }
  set("--save-every", "save_every", args.save_every);
  set("--repair-degenerate", "repair_degenerate", args.repair_degenerate);
  return r;
}

}  // namespace

void add_flow_command(CLI::App& app, std::function<int()>& run) {
  auto args = std::make_shared<FlowArgs>();
  CLI::App* cmd = app.add_subcommand(
      "flow", "Run one flow and write OUT/result.json, OUT/final.ply (and frames).");
  cmd->footer("Mesh specs:\n" + mesh_spec_help() +
              "\nExample:\n  mcfbench flow --mesh sphere:vertices=2000 --flow mcf --basis hat "
              "--solver cholmod "
              "--dt 1e-3 --steps 20 --out out/sphere\n");
  add_flow_options(*cmd, *args);

  run = nullptr;
  cmd->callback([cmd, args, &run] {
    run = [cmd, args]() -> int { return run_flow_into_folder(flow_request(*cmd, *args)); };
  });
}

}  // namespace mcf
