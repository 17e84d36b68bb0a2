#include "flows/memory_estimate.h"

#include "bases/octree.h"
#include "datasets/validate.h"
#include "flows/registry.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace mcf {
namespace {

// Bytes per input vertex and per octree function, least-squares fits (relative error) to the peak
// resident memory of one-step flows on the armadillo at 52k, 208k and 832k faces and a 200k-face
// sphere, octree depths 6 to 9 (docs/benchmarks.md "Peak memory and set-up"). Each fit was within
// 12% of every measured peak it was fitted to.
constexpr double kHatPerVertex = 1066;              // mesh, half-edge check, M, K, the system
constexpr double kHatCholmodPerVertex = 730;        // the supernodal factor of the surface graph
constexpr double kTrackedPerVertex = 883;           // mesh, stencils, per-triangle cubature data
constexpr double kTrackedPerFunction = 1461;        // M, K, S and the sum, hierarchy, vectors
constexpr double kRebuiltPerVertex = 697;           // mesh, clipped pieces of the working mesh
constexpr double kRebuiltPerFunction = 1821;        // as tracked, plus the pattern built each step
constexpr double kOctreeCholmodPerFunction = 1154;  // the factor of the band's 27-point graph
constexpr double kDensePerUnknown2 = 16;            // the dense matrix and its LLT, 8 bytes each
// The hat basis's surface hierarchy with the multigrid's levels and buffers (the armadillo at 832k
// faces: 627-664 MiB against 449 MiB with PCG).
constexpr double kHatMultigridPerVertex = 480;

// PETSc (solvers/petsc_solver.h): a model, not a fit. Its AIJ copy of the system costs 12 bytes a
// nonzero (value and column index) and the set-up copies of the values and indices 12 more; the
// smoothed-aggregation hierarchy (GAMG, BoomerAMG) and its Galerkin products add about twice the
// finest matrix again, so 3 matrices in all; and the KSP's vectors (CG's four, the three of the
// solve, the hierarchy's smoothers') about 16 doubles per unknown. Nonzeros per row: 7 on a
// triangle mesh (the vertex and its neighbours), at most 27 for the octree's trilinear functions.
constexpr double kPetscMatrixCopies = 3;
constexpr double kPetscBytesPerNonzero = 12 + 12.0 / kPetscMatrixCopies;
constexpr double kPetscVectorBytesPerUnknown = 16 * 8;
constexpr double kHatNonzerosPerRow = 7;
constexpr double kOctreeNonzerosPerRow = 27;

/// About this many finest functions per (h^2 of surface): measured 2.84-3.02 on the armadillo,
/// the elephant and spheres at depths 6 to 9.
constexpr double kFunctionsPerArea = 3.0;

}  // namespace

std::string format_gib(double bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f GiB", bytes / double(1ull << 30));
  return text;
}

nlohmann::json MemoryEstimate::to_json() const {
  return {
      {"bytes", total()},           {"resident_bytes", resident_bytes}, {"mesh_bytes", mesh_bytes},
      {"basis_bytes", basis_bytes}, {"solver_bytes", solver_bytes},     {"dimension", dimension},
      {"vertices", vertices},       {"lower_bound", lower_bound}};
}

std::string MemoryEstimate::describe(const FlowConfig& config) const {
  char sizes[96];
  if (lower_bound)
    std::snprintf(sizes, sizeof sizes, "%.3g vertices; the octree not counted", vertices);
  else
    std::snprintf(sizes, sizeof sizes, "%.3g unknowns", dimension);
  std::string what =
      format_gib(total()) + (lower_bound ? " at least" : "") + " (" + config.basis + " basis";
  if (config.basis == "octree") what += " depth " + std::to_string(config.octree.depth);
  return what + ", " + config.solver.name + ": " + sizes + ")";
}

FlowSizes spec_sizes(const MeshSpecRequest& request) {
  FlowSizes s;
  s.faces = std::max(request.generated_faces, double(request.target_faces));
  s.vertices = s.faces / 2;
  return s;
}

FlowSizes mesh_sizes(const FlowConfig& config, const TriangleMesh& mesh, bool analytic) {
  FlowSizes s;
  s.exact = true;
  const double split = config.octree.refine_input ? 4.0 : 1.0;
  s.faces = double(mesh.faces.rows()) * split;
  // A 1-to-4 split adds one vertex per edge: about 3/2 per face.
  s.vertices = double(mesh.vertices.rows()) + (split - 1.0) / 2.0 * double(mesh.faces.rows());
  if (config.basis != "octree") return s;
  try {
    const GridCube cube =
        choose_cube(mesh, config.octree.depth, octree_options(config.octree, analytic).cube);
    s.area_over_side2 = surface_area(mesh) / (cube.side * cube.side);
  } catch (const std::invalid_argument&) {
    // The basis refuses this cube with its own message.
  }
  return s;
}

double estimated_octree_dimension(double area_over_side2, int depth) {
  return kFunctionsPerArea * area_over_side2 * std::ldexp(1.0, 2 * depth);
}

MemoryEstimate estimate_flow_memory(const FlowConfig& config, const FlowSizes& sizes,
                                    double resident_bytes) {
  MemoryEstimate e;
  e.resident_bytes = resident_bytes;
  e.vertices = sizes.vertices;
  const bool cholmod = config.solver.name == "cholmod";
  if (config.basis == "octree") {
    const bool rebuilt = config.octree.tracking == "rebuilt";
    e.mesh_bytes = (rebuilt ? kRebuiltPerVertex : kTrackedPerVertex) * sizes.vertices;
    if (sizes.area_over_side2 < 0) {
      e.lower_bound = true;
      return e;
    }
    e.dimension = estimated_octree_dimension(sizes.area_over_side2, config.octree.depth);
    e.basis_bytes = (rebuilt ? kRebuiltPerFunction : kTrackedPerFunction) * e.dimension;
  } else {
    e.dimension = sizes.vertices;
    e.mesh_bytes = kHatPerVertex * sizes.vertices;
  }
  const SolverConfig& solver = config.solver;
  const bool multigrid =
      solver.name == "multigrid" || (solver.name == "pcg" && solver.preconditioner == "multigrid");
  if (config.basis != "octree" && multigrid)
    e.solver_bytes = kHatMultigridPerVertex * e.dimension;
  else if (cholmod)
    e.solver_bytes =
        (config.basis == "octree" ? kOctreeCholmodPerFunction : kHatCholmodPerVertex) * e.dimension;
  else if (solver.name == "petsc")
    e.solver_bytes = (kPetscMatrixCopies * kPetscBytesPerNonzero *
                          (config.basis == "octree" ? kOctreeNonzerosPerRow : kHatNonzerosPerRow) +
                      kPetscVectorBytesPerUnknown) *
                     e.dimension;
  else if (config.solver.name == "dense")
    e.solver_bytes = kDensePerUnknown2 * e.dimension * e.dimension;
  return e;
}

}  // namespace mcf
