#include "config/basis_registry.h"

#include "bases/hat_basis.h"
#include "bases/octree.h"
#include "bases/tracked_octree_basis.h"
#include "config/config_reader.h"
#include "config/solver_registry.h"
#include "datasets/subdivide.h"
#include "datasets/validate.h"

#include <stdexcept>

namespace mcf {
namespace {

// octree.stabilization_weight recorded where the system carries no such term (the hat basis, the
// paper's system): the value every config recorded before the weight became the solver's, so
// that those cells keep their config keys (harness/cell_hash.h). It changes nothing there.
constexpr double kInertStabilizationWeight = 0.5;

// octree.stabilization_weight where the config leaves it out, by how the solver solves. The
// iterative solvers converge faster the larger the weight (the cycles need about 0.3: 0.5); a
// direct solver needs only a definite system, which 1e-6 gives where faces parallel to the grid
// planes leave the paper's system singular, while moving its surface by about 1e-5 relative
// (docs/octree-multigrid.md, "Stabilization").
constexpr double kIterativeStabilizationWeight = 0.5;

// Bytes per input vertex and per octree function, least-squares fits (relative error) to the peak
// resident memory of one-step flows on the armadillo at 52k, 208k and 832k faces and a 200k-face
// sphere, octree depths 6 to 9 (docs/benchmarks.md "Peak memory and set-up"). Each fit was within
// 12% of every measured peak it was fitted to.
constexpr double kHatPerVertex = 1066;        // mesh, half-edge check, M, K, the system
constexpr double kHatCholmodPerVertex = 730;  // the supernodal factor of the surface graph
constexpr double kTrackedPerVertex = 883;     // mesh, stencils, per-triangle cubature data
// Tracked: 1461 fitted, plus 240 for the multigrid's Galerkin plans (solvers/galerkin.h; +78 MB
// over 322k functions on the armadillo at 200k faces, depth 8). A rebuilt basis's pattern is new
// every step, so it builds none.
constexpr double kTrackedPerFunction = 1461 + 240;  // M, K, S and the sum, hierarchy, vectors
constexpr double kRebuiltPerVertex = 697;           // mesh, clipped pieces of the working mesh
constexpr double kRebuiltPerFunction = 1821;        // as tracked, plus the pattern built each step
constexpr double kOctreeCholmodPerFunction = 1154;  // the factor of the band's 27-point graph
// The hat basis's surface hierarchy with the multigrid's levels and buffers (the armadillo at 832k
// faces: 627-664 MiB against 449 MiB with PCG).
constexpr double kHatMultigridPerVertex = 480;
// Nonzeros per row: 7 on a triangle mesh (the vertex and its neighbours), at most 27 for the
// octree's trilinear functions.
constexpr double kHatNonzerosPerRow = 7;
constexpr double kOctreeNonzerosPerRow = 27;

std::unique_ptr<Basis> make_hat(const FlowConfig& config, const TriangleMesh& mesh, bool,
                                bool hierarchy) {
  // The surface hierarchy only where a multigrid uses it: it costs set-up time and memory.
  std::optional<SurfaceHierarchyOptions> levels;
  if (hierarchy) levels = SurfaceHierarchyOptions{};
  const MassKind mass = config.mass == "lumped" ? MassKind::lumped : MassKind::consistent;
  if (config.octree.refine_input)  // the 1-to-4 split flows; the input's vertices are output
    return std::make_unique<HatBasis>(subdivide_midpoint(mesh), mass, levels, mesh.num_vertices());
  return std::make_unique<HatBasis>(mesh, mass, levels);
}

BasisRow hat_row() {
  BasisRow hat{"hat", "P1 hat functions on the mesh, cotangent stiffness", make_hat,
               [](const FlowConfig&, const FlowSizes& s) {
                 BasisMemory m;
                 m.dimension = s.vertices;
                 m.mesh_bytes = kHatPerVertex * s.vertices;
                 return m;
               }};
  hat.system.nonzeros_per_row = kHatNonzerosPerRow;
  hat.system.factor_bytes_per_unknown = kHatCholmodPerVertex;
  hat.system.hierarchy_bytes_per_unknown = kHatMultigridPerVertex;
  hat.takes_mass = true;
  return hat;
}

std::vector<OptionSpec> octree_row_options() {
  OptionSpec tracking = bind(
      option("octree.tracking", OptionType::string, "tracked", "--tracking",
             "Octree: how the basis follows the surface"),
      [](auto& c) -> auto& { return c.octree.tracking; });
  tracking.choices = [] { return tracking_table().choices(); };
  OptionSpec depth = ranged(bind(
                                option("octree.depth", OptionType::integer, 8, "--depth",
                                       "Octree depth (the finest level)"),
                                [](auto& c) -> auto& { return c.octree.depth; }),
                            4, 10);
  OptionSpec cubature = ranged(
      bind(
          option("octree.cubature", OptionType::integer, 3, "--cubature",
                 "Octree cubature rule per split triangle: the centroid, the paper's 3-point "
                 "rule or Dunavant's degree-6 rule"),
          [](auto& c) -> auto& { return c.octree.cubature; }),
      1, 6);
  cubature.values_text = "1 | 3 | 6";
  cubature.after = [](FlowConfig& c, const ConfigReader& r, const std::string& leaf) {
    const int n = c.octree.cubature;
    if (n != 1 && n != 3 && n != 6) r.fail(leaf, "must be 1, 3 or 6, got " + std::to_string(n));
  };
  OptionSpec cube = bind(
      option("octree.cube", OptionType::string, "auto", "--cube", "Octree bounding cube"),
      [](auto& c) -> auto& { return c.octree.cube; });
  cube.choices = [] {
    return std::vector<Choice>{
        {"auto", "the unit cube if the mesh fits in it, else the tight cube"},
        {"unit", "the unit cube; a mesh outside it is refused"},
        {"tight", "the cube around the mesh"}};
  };
  OptionSpec refine = bind(
      option("octree.refine_input", OptionType::boolean, false, "--refine-input",
             "Split the input mesh 1-to-4 once first (octree and hat basis); "
             "only its vertices are output"),
      [](auto& c) -> auto& { return c.octree.refine_input; });
  refine.flag_kind = FlagKind::set_true;
  refine.selected = [](const FlowConfig&) { return true; };  // read by the hat basis as well
  OptionSpec stabilization = bind(
      option("octree.stabilization", OptionType::string, "normal-gradient", "--stabilization",
             "Octree system (docs/octree-multigrid.md)"),
      [](auto& c) -> auto& { return c.octree.stabilization; });
  stabilization.choices = [] {
    return std::vector<Choice>{
        {"none", "the paper's system"},
        {"normal-gradient",
         "solve each step's increment with the band's normal-gradient term added, so that "
         "multigrid converges"}};
  };
  OptionSpec weight = ranged(
      bind(
          option("octree.stabilization_weight", OptionType::number, -1, "--stabilization-weight",
                 "Octree: c, the normal-gradient term's diagonal over the system's"),
          [](auto& c) -> auto& { return c.octree.stabilization_weight; }),
      0, 1e6);
  weight.default_text = "the solver's (0.5; cholmod, dense 1e-6)";
  // Elsewhere the config records the inert value (kInertStabilizationWeight), which is no
  // request; any other value is refused.
  weight.owner = "octree";
  weight.owner_text = "basis \"octree\"";
  weight.refused_elsewhere = true;
  weight.matrix_drops = true;
  weight.selected = [](const FlowConfig& c) {
    return c.basis == "octree" || c.octree.stabilization_weight == kInertStabilizationWeight;
  };
  return {tracking, depth, cubature, cube, refine, stabilization, weight};
}

BasisRow octree_row() {
  BasisRow octree{"octree", "trilinear B-splines on an octree around the surface",
                  [](const FlowConfig& config, const TriangleMesh& mesh, bool analytic, bool) {
                    return tracking_row(config.octree.tracking)
                        .make(mesh, octree_options(config.octree, analytic));
                  },
                  [](const FlowConfig& config, const FlowSizes& s) {
                    const TrackingRow& t = tracking_row(config.octree.tracking);
                    BasisMemory m;
                    m.mesh_bytes = t.bytes_per_vertex * s.vertices;
                    if (s.area_over_side2 < 0) {
                      m.lower_bound = true;
                      return m;
                    }
                    m.dimension =
                        estimated_octree_dimension(s.area_over_side2, config.octree.depth);
                    m.basis_bytes = t.bytes_per_function * m.dimension;
                    return m;
                  }};
  octree.options = octree_row_options();
  octree.system.nonzeros_per_row = kOctreeNonzerosPerRow;
  octree.system.factor_bytes_per_unknown = kOctreeCholmodPerFunction;
  // The octree's hierarchy is its own (in bytes_per_function).
  octree.size = [](const FlowConfig& config, const TriangleMesh& mesh, bool analytic,
                   FlowSizes& s) {
    try {
      const GridCube cube =
          choose_cube(mesh, config.octree.depth, octree_options(config.octree, analytic).cube);
      s.area_over_side2 = surface_area(mesh) / (cube.side * cube.side);
    } catch (const std::invalid_argument&) {
      // The basis refuses this cube with its own message.
    }
  };
  octree.fixed_functions = [](const FlowConfig& config) {
    return tracking_row(config.octree.tracking).fixed_functions;
  };
  octree.stabilization = [](const FlowConfig& config) -> std::optional<double> {
    if (!octree_options(config.octree, false).normal_gradient) return std::nullopt;
    const double c = config.octree.stabilization_weight;  // < 0 in a config not read from JSON
    if (c >= 0) return c;
    return solver_row(config.solver.name).iterative ? kIterativeStabilizationWeight
                                                    : kDefiniteStabilizationWeight;
  };
  octree.describe = [](const FlowConfig& config) {
    return " depth " + std::to_string(config.octree.depth);
  };
  octree.keeps_degenerate_faces = true;
  return octree;
}

void check(const BasisRow& row) {
  if (!row.make || !row.memory)
    throw std::logic_error("basis \"" + row.name +
                           "\" registered without a factory or a memory model");
}

NamedTable<BasisRow>& table() {
  static NamedTable<BasisRow> t = [] {
    NamedTable<BasisRow> b("basis", check);
    for (BasisRow row : {hat_row(), octree_row()}) b.add(std::move(row));
    return b;
  }();
  return t;
}

}  // namespace

const NamedTable<BasisRow>& basis_table() {
  return table();
}

void register_basis(BasisRow row) {
  table().add(std::move(row));
}

const BasisRow& basis_row(const std::string& name) {
  return table().at(name);
}

const NamedTable<TrackingRow>& tracking_table() {
  static const NamedTable<TrackingRow> t = [] {
    NamedTable<TrackingRow> r("octree tracking");
    r.add({"tracked", "built once, its metric re-integrated every step",
           [](const TriangleMesh& mesh, const OctreeOptions& o) -> std::unique_ptr<Basis> {
             return std::make_unique<TrackedOctreeBasis>(mesh, o);
           },
           kTrackedPerVertex, kTrackedPerFunction, true});
    r.add({"rebuilt", "built anew around the surface every step",
           [](const TriangleMesh& mesh, const OctreeOptions& o) -> std::unique_ptr<Basis> {
             return std::make_unique<RebuiltOctreeBasis>(mesh, o);
           },
           kRebuiltPerVertex, kRebuiltPerFunction, false});
    return r;
  }();
  return t;
}

const TrackingRow& tracking_row(const std::string& name) {
  return tracking_table().at(name);
}

OctreeOptions octree_options(const OctreeConfig& c, bool analytic) {
  OctreeOptions o;
  o.depth = c.depth;
  o.cubature = c.cubature;
  o.refine_input = c.refine_input;
  o.normal_gradient = c.stabilization == "normal-gradient";
  // "auto": the unit cube for models normalised into it (the paper's setting), the tight cube
  // around analytic shapes (which keep their own size).
  if (c.cube == "unit")
    o.cube = OctreeCube::unit;
  else if (c.cube == "tight")
    o.cube = OctreeCube::tight;
  else
    o.cube = analytic ? OctreeCube::tight : OctreeCube::automatic;
  return o;
}

void resolve_stabilization_weight(FlowConfig& c) {
  if (c.octree.stabilization_weight >= 0) return;
  const BasisRow& basis = basis_row(c.basis);
  const std::optional<double> weight = basis.stabilization ? basis.stabilization(c) : std::nullopt;
  c.octree.stabilization_weight = weight ? *weight : kInertStabilizationWeight;
}

}  // namespace mcf
