#include "flows/flow_config.h"

#include "flows/config_reader.h"
#include "flows/integrator.h"

namespace mcf {

FlowConfig flow_config_from_json(const nlohmann::json& j, const std::string& source) {
  ConfigReader r(j, source);
  FlowConfig c;
  c.mesh = r.get_string("mesh", "");
  if (c.mesh.empty()) r.fail("mesh", "missing (a mesh spec such as \"sphere:vertices=2000\")");
  c.flow = r.get_string("flow", c.flow, {"mcf", "cmcf", "heat"});
  c.basis = r.get_string("basis", c.basis, {"hat", "octree"});
  c.mass = r.get_string("mass", c.mass, {"consistent", "lumped"});
  {
    auto o = r.child("octree");
    c.octree.tracking = o.get_string("tracking", c.octree.tracking, {"tracked", "rebuilt"});
    c.octree.depth = int(o.get_integer("depth", c.octree.depth, 4, 10));
    c.octree.cubature = int(o.get_integer("cubature", c.octree.cubature, 1, 6));
    if (c.octree.cubature != 1 && c.octree.cubature != 3 && c.octree.cubature != 6)
      o.fail("cubature", "must be 1, 3 or 6, got " + std::to_string(c.octree.cubature));
    c.octree.cube = o.get_string("cube", c.octree.cube, {"auto", "unit", "tight"});
    c.octree.refine_input = o.get_bool("refine_input", c.octree.refine_input);
    c.octree.stabilization =
        o.get_string("stabilization", c.octree.stabilization, {"none", "normal-gradient"});
    c.octree.stabilization_weight =
        o.get_number("stabilization_weight", c.octree.stabilization_weight, 0.0, 1e6);
    o.finish();
  }
  {
    auto s = r.child("solver");
    c.solver.name =
        s.get_string("name", c.solver.name, {"cholmod", "pcg", "multigrid", "petsc", "dense"});
    // PETSc's default cap is the paper's baseline's: CG + AMG stopped at 3000 iterations.
    if (c.solver.name == "petsc") c.solver.max_iterations = 3000;
    c.solver.tolerance =
        s.get_number("tolerance", c.solver.tolerance, 0, 1);  // absent: -1, the solver's default
    c.solver.max_iterations =
        int(s.get_integer("max_iterations", c.solver.max_iterations, 1, 100000000));
    c.solver.preconditioner = s.get_string("preconditioner", c.solver.preconditioner,
                                           {"none", "jacobi", "ichol", "multigrid"});
    c.solver.cycle = s.get_string("cycle", c.solver.cycle, {"V", "W"});
    c.solver.cycles = int(s.get_integer("cycles", c.solver.cycles, 1, 10000));
    c.solver.smooth = int(s.get_integer("smooth", c.solver.smooth, 0, 1000));
    c.solver.stall_ratio = s.get_number("stall_ratio", c.solver.stall_ratio, 0, 1);
    c.solver.fallback_tolerance =
        s.get_number("fallback_tolerance", c.solver.fallback_tolerance, 1e-300, 1);
    c.solver.petsc_options = s.get_string("petsc_options", c.solver.petsc_options);
    c.solver.galerkin_by_term = s.get_bool("galerkin_by_term", c.solver.galerkin_by_term);
    c.solver.precision = s.get_string("precision", c.solver.precision, {"double", "mixed"});
    s.finish();
  }
  c.integrator = r.get_string("integrator", c.integrator, integrator_names());
  c.extrapolate = r.get_bool("extrapolate", c.extrapolate);
  c.dt = r.get_number("dt", c.dt, 1e-300, 1e6);
  if (c.dt <= 0) r.fail("dt", "must be > 0");
  c.steps = int(r.get_integer("steps", c.steps, 0, 100000000));
  c.normalize_area = r.get_bool("normalize_area", c.normalize_area);
  c.threads = int(r.get_integer("threads", c.threads, 0, 4096));
  c.blas_threads = int(r.get_integer("blas_threads", c.blas_threads, 0, 4096));
  c.save_every = int(r.get_integer("save_every", c.save_every, 0, 100000000));
  c.repair_degenerate = r.get_bool("repair_degenerate", c.repair_degenerate);
  r.finish();
  if (c.solver.tolerance < 0) c.solver.tolerance = c.solver.name == "multigrid" ? 0.0 : 1e-10;
  validate_flow_config(c, source);
  return c;
}

nlohmann::json to_json(const FlowConfig& c) {
  nlohmann::json j = {{"mesh", c.mesh},
                      {"flow", c.flow},
                      {"basis", c.basis},
                      {"mass", c.mass},
                      {"octree",
                       {{"tracking", c.octree.tracking},
                        {"depth", c.octree.depth},
                        {"cubature", c.octree.cubature},
                        {"cube", c.octree.cube},
                        {"refine_input", c.octree.refine_input},
                        {"stabilization", c.octree.stabilization},
                        {"stabilization_weight", c.octree.stabilization_weight}}},
                      {"solver",
                       {{"name", c.solver.name},
                        {"tolerance", c.solver.tolerance},
                        {"max_iterations", c.solver.max_iterations},
                        {"preconditioner", c.solver.preconditioner},
                        {"cycle", c.solver.cycle},
                        {"cycles", c.solver.cycles},
                        {"smooth", c.solver.smooth}}},
                      {"integrator", c.integrator},
                      {"extrapolate", c.extrapolate},
                      {"dt", c.dt},
                      {"steps", c.steps},
                      {"normalize_area", c.normalize_area},
                      {"threads", c.threads},
                      {"blas_threads", c.blas_threads},
                      {"save_every", c.save_every}};
  // Only when set: a key present with its default would change the config key of every cell
  // (bench/cell_hash.h), and `compare` would find no cell of an earlier run to compare with.
  if (c.repair_degenerate) j["repair_degenerate"] = true;
  // A solver's own options only where that solver runs, for the same reason: the config keys of
  // the other solvers' cells stay those of versions without them.
  if (c.solver.name == "petsc") j["solver"]["petsc_options"] = c.solver.petsc_options;
  if (c.solver.galerkin_by_term) j["solver"]["galerkin_by_term"] = true;
  if (c.solver.precision != "double") j["solver"]["precision"] = c.solver.precision;
  if (c.solver.name == "multigrid") {
    j["solver"]["stall_ratio"] = c.solver.stall_ratio;
    j["solver"]["fallback_tolerance"] = c.solver.fallback_tolerance;
  }
  return j;
}

void validate_flow_config(const FlowConfig& c, const std::string& source) {
  auto fail = [&](const std::string& key, const std::string& what) {
    throw ConfigError(source + ": " + key + ": " + what);
  };
  const bool rebuilt = c.basis == "octree" && c.octree.tracking == "rebuilt";
  // Options no solver reads would be recorded as if they had shaped the run.
  if (c.solver.name != "petsc" && !c.solver.petsc_options.empty())
    fail("solver.petsc_options",
         "applies to solver \"petsc\" only, the solver is \"" + c.solver.name + "\"");
  const bool multigrid = c.solver.name == "multigrid" ||
                         (c.solver.name == "pcg" && c.solver.preconditioner == "multigrid");
  if (c.solver.galerkin_by_term && !multigrid)
    fail("solver.galerkin_by_term",
         "applies to a multigrid (solver \"multigrid\", or \"pcg\" "
         "with preconditioner \"multigrid\") only");
  if (c.solver.precision != "double" && !multigrid)
    fail("solver.precision", "\"" + c.solver.precision +
                                 "\" applies to a multigrid (solver \"multigrid\", or \"pcg\" "
                                 "with preconditioner \"multigrid\") only");
  // Accepting it would record a lumped mass the flow never used (and duplicate an axis's cells).
  if (c.basis != "hat" && c.mass != "consistent")
    fail("mass", "\"" + c.mass +
                     "\" applies to the hat basis only; the octree basis integrates its "
                     "consistent mass matrix by cubature");
  if (rebuilt && c.flow == "cmcf")
    fail("flow",
         "cmcf keeps the stiffness of t=0, which needs a fixed basis; the rebuilt octree "
         "changes its functions every step (use octree.tracking \"tracked\" or basis \"hat\")");
  if (rebuilt && c.flow == "heat")
    fail("flow",
         "heat flow keeps the operators of t=0, which needs a fixed basis; the rebuilt "
         "octree changes its functions every step");
  if (rebuilt && (c.integrator == "bdf2" || c.integrator == "crank-nicolson"))
    fail("integrator",
         "two-step schemes need coefficients in one fixed basis; the rebuilt octree "
         "changes its functions every step");
}

void validate_flow_mesh(const FlowConfig& c, const MeshReport& mesh, const std::string& source) {
  // An open surface's boundary is held where it is (docs/design.md "Conventions"; the cMCF paper
  // flows an open surface with its boundary fixed), while unit-area normalisation rescales and
  // recentres the whole surface every step: the held boundary would move with it (a loop grew by
  // 24% in 8 steps of cMCF on the mannequin). The two contradict each other, so refuse.
  if (c.normalize_area && mesh.boundary_loops > 0)
    throw ConfigError(
        source + ": normalize_area: the mesh has " + std::to_string(mesh.boundary_loops) +
        " boundary loop(s), held fixed through the flow, which rescaling to unit area every "
        "step would move; run an open surface without normalize_area (leave out "
        "--normalize-area, or set \"normalize_area\": false): its boundary stays where it is and "
        "a time step then means what it does at the mesh's own size (files are scaled into the "
        "unit cube), or close its holes first to flow it at unit area");
}

MeshLoadOptions mesh_load_options(const FlowConfig& c) {
  MeshLoadOptions o;
  if (c.repair_degenerate) {
    o.degenerate = DegenerateFaces::repair;
  } else if (c.basis == "octree") {
    // The octree basis integrates over the surface by cubature on clipped pieces, and a
    // zero-area face leaves no piece: it changes nothing there.
    o.degenerate = DegenerateFaces::keep;
  } else {
    o.degenerate_hint =
        ": the hat basis needs every face's cotangents, which a zero-area face lacks; "
        "--repair-degenerate (config key repair_degenerate) removes zero-area faces, or "
        "--basis octree takes them as they are";
  }
  return o;
}

}  // namespace mcf
