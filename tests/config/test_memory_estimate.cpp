// The memory estimate's sizes against what the bases build: the octree's function count predicted
// from the area against the built basis, a spec's sizes against the generated mesh, and the
// estimate's shares growing with what they are said to grow with.

#include "bases/tracked_octree_basis.h"
#include "config/flow_config.h"
#include "config/memory_estimate.h"
#include "config/registry.h"
#include "datasets/mesh_spec.h"

#include <gtest/gtest.h>

namespace mcf {
namespace {

FlowConfig config(const nlohmann::json& j) {
  return flow_config_from_json(j, "test");
}

TEST(MemoryEstimate, OctreeDimensionFromTheAreaMatchesTheBuiltBasis) {
  for (const char* spec : {"sphere:vertices=4000", "torus", "dumbbell"})
    for (int depth : {5, 6}) {
      const MeshSource source = load_mesh_spec(spec);
      const FlowConfig c =
          config({{"mesh", spec}, {"basis", "octree"}, {"octree", {{"depth", depth}}}});
      const FlowSizes sizes = mesh_sizes(c, source.mesh, source.analytic);
      ASSERT_GT(sizes.area_over_side2, 0) << spec;
      const TrackedOctreeBasis basis(source.mesh, octree_options(c.octree, source.analytic));
      const double predicted = estimated_octree_dimension(sizes.area_over_side2, depth);
      const double built = double(basis.dimension());
      EXPECT_GT(predicted, 0.7 * built) << spec << " depth " << depth << " built " << built;
      EXPECT_LT(predicted, 1.3 * built) << spec << " depth " << depth << " built " << built;
    }
}

TEST(MemoryEstimate, SpecSizesMatchTheGeneratedMesh) {
  for (const char* spec : {"sphere:vertices=5000", "icosphere:level=4", "torus"}) {
    const FlowSizes s = spec_sizes(parse_mesh_spec(spec));
    const MeshSource m = load_mesh_spec(spec);
    EXPECT_FALSE(s.exact);
    EXPECT_GE(s.faces, 0.95 * double(m.mesh.faces.rows())) << spec;
    EXPECT_LE(s.faces, 1.5 * double(m.mesh.faces.rows())) << spec;
    EXPECT_NEAR(s.vertices, double(m.mesh.vertices.rows()), 0.05 * double(m.mesh.vertices.rows()))
        << spec;
  }
  // "@faces=N": at least N faces.
  EXPECT_GE(spec_sizes(parse_mesh_spec("icosphere:level=2@faces=10000")).faces, 10000);
  // A file's size is its own: nothing known before it is read.
  EXPECT_EQ(spec_sizes(parse_mesh_spec("missing.off")).faces, 0);
}

TEST(MemoryEstimate, OctreeWithoutItsSizeIsALowerBound) {
  const FlowConfig c = config({{"mesh", "torus"}, {"basis", "octree"}});
  const MemoryEstimate spec = estimate_flow_memory(c, spec_sizes(parse_mesh_spec("torus")), 0);
  const MeshSource m = load_mesh_spec("torus");
  const MemoryEstimate full = estimate_flow_memory(c, mesh_sizes(c, m.mesh, m.analytic), 0);
  EXPECT_TRUE(spec.lower_bound);
  EXPECT_FALSE(full.lower_bound);
  EXPECT_EQ(spec.basis_bytes, 0);
  EXPECT_GT(full.basis_bytes, 0);
  EXPECT_LT(spec.total(), full.total());
}

TEST(MemoryEstimate, SharesGrowWithDepthMeshAndFactor) {
  FlowSizes s;
  s.vertices = 1e5;
  s.faces = 2e5;
  s.area_over_side2 = 1.5;
  auto total = [&](const nlohmann::json& j) {
    return estimate_flow_memory(config(j), s, 1e7).total();
  };
  const nlohmann::json octree = {
      {"mesh", "x"}, {"basis", "octree"}, {"solver", {{"name", "multigrid"}}}};
  nlohmann::json deeper = octree;
  deeper["octree"]["depth"] = 9;
  EXPECT_GT(total(deeper), 3.5 * (total(octree) - 1e7));  // four times the functions, ~ the bytes
  nlohmann::json factored = octree;
  factored["solver"]["name"] = "cholmod";
  EXPECT_GT(total(factored), total(octree));
  EXPECT_GT(total({{"mesh", "x"}, {"solver", {{"name", "cholmod"}}}}),
            total({{"mesh", "x"}, {"solver", {{"name", "pcg"}}}}));
  // PETSc: its copy of the matrix and the AMG hierarchy, about three matrices, and more for the
  // octree's 27-point rows than for a triangle mesh's 7.
  const auto petsc = [&](const nlohmann::json& j) { return estimate_flow_memory(config(j), s, 0); };
  const MemoryEstimate hat_petsc = petsc({{"mesh", "x"}, {"solver", {{"name", "petsc"}}}});
  EXPECT_GT(hat_petsc.solver_bytes, 3 * 12 * 7 * 1e5);
  EXPECT_LT(hat_petsc.solver_bytes, 1000 * 1e5);
  nlohmann::json octree_petsc = octree;
  octree_petsc["solver"]["name"] = "petsc";
  EXPECT_GT(petsc(octree_petsc).solver_bytes / petsc(octree_petsc).dimension,
            2 * hat_petsc.solver_bytes / hat_petsc.dimension);
  // The dense reference stores n^2 doubles and their factor.
  EXPECT_GE(total({{"mesh", "x"}, {"solver", {{"name", "dense"}}}}), 16 * 1e5 * 1e5);
  // The resident memory is part of the total.
  EXPECT_DOUBLE_EQ(estimate_flow_memory(config(octree), s, 5e8).total() -
                       estimate_flow_memory(config(octree), s, 0).total(),
                   5e8);
}

TEST(MemoryEstimate, RefinedInputCountsFourTimesTheFaces) {
  const MeshSource m = load_mesh_spec("icosphere:level=3");
  const FlowConfig plain = config({{"mesh", "x"}, {"basis", "octree"}});
  const FlowConfig refined =
      config({{"mesh", "x"}, {"basis", "octree"}, {"octree", {{"refine_input", true}}}});
  const FlowSizes a = mesh_sizes(plain, m.mesh, m.analytic),
                  b = mesh_sizes(refined, m.mesh, m.analytic);
  EXPECT_EQ(b.faces, 4 * a.faces);
  EXPECT_EQ(b.vertices, double(load_mesh_spec("icosphere:level=4").mesh.vertices.rows()));
  EXPECT_DOUBLE_EQ(a.area_over_side2, b.area_over_side2);
}

}  // namespace
}  // namespace mcf
