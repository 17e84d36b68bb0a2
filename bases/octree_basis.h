#pragma once
// The rebuilt octree basis (docs/design.md "The octree basis", rebuilt): the CLB*09
// baseline that builds the octree, clips the mesh and integrates with the identity metric on the
// current vertex positions at every step.

#include "bases/basis.h"
#include "bases/clip.h"
#include "bases/cubature.h"
#include "bases/octree.h"
#include "bases/octree_system.h"
#include "datasets/validate.h"  // boundary_edges

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace mcf {

struct OctreeOptions {
  int depth = 8;     ///< finest depth, 4..10
  int cubature = 3;  ///< 1, 3 or 6 (cubature_rule)
  OctreeCube cube = OctreeCube::automatic;
  bool refine_input = false;  ///< 1-to-4 split of the initial mesh first
  int coarsest_depth = 2;     ///< coarsest multigrid level (clamped to depth)
  /// Also assemble the band's normal-gradient matrix (Basis::normal_gradient), for flows that
  /// stabilize their increments; it costs one more value array on the pattern.
  bool normal_gradient = false;
};

class RebuiltOctreeBasis : public Basis {
 public:
  /// Builds from the mesh's initial positions (faces are fixed from now on).
  explicit RebuiltOctreeBasis(const TriangleMesh& mesh, OctreeOptions options = {});
  RebuiltOctreeBasis(const RebuiltOctreeBasis&) = delete;  // the system points into members
  RebuiltOctreeBasis& operator=(const RebuiltOctreeBasis&) = delete;

  std::string name() const override { return "octree-rebuilt"; }
  Eigen::Index dimension() const override;
  bool rebuilds_every_step() const override { return true; }
  /// Rebuilds octree, pieces, matrices and hierarchy on `vertices` (rows = the input mesh's
  /// vertex count). With refine_input the midpoint vertices come from the last
  /// evaluate_vertices call when there was one on the current basis, else from the edges'
  /// midpoints.
  void rebuild(const Positions& vertices) override;
  /// With refine_input: moves the last evaluation's midpoints with the flow's normalisation, so
  /// that rebuild() recognises the normalised vertices and keeps the flowed midpoints.
  void reframe(const Eigen::RowVector3d& centroid, double scale) override;
  /// x_0^I = c_I, the grid-vertex positions of the finest functions.
  Coefficients initial_coefficients() const override;
  /// The matrices integrated by rebuild() are those of the identity metric, i.e. of x =
  /// initial_coefficients(); this basis cannot re-integrate at another embedding, so update() is a
  /// no-op (it only checks the dimension). Call rebuild() to move to a new embedding.
  void update(const Coefficients& x, bool update_mass, bool update_stiffness) override;
  /// On the system's pattern (OctreeSystem::view): one copy of the index arrays for both.
  SparseView mass() const override;
  SparseView stiffness() const override;
  /// With options().normal_gradient: S on the current mesh's band (rebuilt with the basis).
  SparseView normal_gradient() const override;
  /// v = Σ_I B_I(v) x^I for the input mesh's vertices (trilinear stencils in an active finest
  /// cell). Vertices used by no face keep the position they had at the last rebuild.
  Positions evaluate_vertices(const Coefficients& x) const override;
  /// Open surfaces: finest functions whose support meets a boundary edge (see boundary_functions).
  std::vector<int> locked_functions() const override { return locked_; }
  const std::vector<SparseMatrix>* prolongations() const override { return &prolongations_; }
  const std::vector<std::vector<std::uint8_t>>* colours() const override { return &colours_; }
  const BasisStats& stats() const override { return stats_; }

  // Internals, for tests and the tracked basis.
  const OctreeOptions& options() const { return options_; }
  const TriangleMesh& working_mesh() const {
    return mesh_;
  }  ///< the (possibly 1-to-4 refined) mesh integrated
  const Octree& octree() const { return octree_; }
  const std::vector<ClippedTriangle>& pieces() const { return pieces_; }
  const std::vector<int>& piece_cells() const { return piece_cells_; }
  const OctreeSystem& system() const { return *system_; }

  /// For the tracked basis, which from now on re-integrates on this basis's fixed pattern: swaps
  /// the assembled values of mass and stiffness (on system()'s pattern) into `mass` and
  /// `stiffness`, so their memory (allocated and touched already) is reused instead of fresh
  /// zeroed arrays, and frees the pieces and their cells (the tracked basis keeps its own compact
  /// copy), the system's piece order (OctreeSystem::release_pieces) and the vertex stencils (the
  /// tracked basis computes those of the input's vertices). Afterwards mass(), stiffness() and
  /// pieces() are empty, system() can no longer assemble, and evaluate_vertices() throws
  /// std::logic_error; octree, pattern, hierarchy, locked functions and stats stay. rebuild()
  /// starts over from scratch as usual.
  /// The normal-gradient values (with options().normal_gradient) are swapped into
  /// `normal_gradient` the same way.
  void release_assembly(std::vector<double>& mass, std::vector<double>& stiffness,
                        std::vector<double>& normal_gradient);

 private:
  OctreeOptions options_;
  Eigen::Index input_vertices_ = 0;
  TriangleMesh mesh_;
  Octree octree_;
  std::vector<ClippedTriangle> pieces_;
  std::vector<int> piece_cells_;
  std::unique_ptr<OctreeSystem> system_;
  std::vector<double> mass_, stiffness_;  // values on system_'s pattern
  std::vector<double> normal_gradient_;   // options_.normal_gradient: values on the pattern
  std::vector<SparseMatrix> prolongations_;
  std::vector<std::vector<std::uint8_t>> colours_;
  VertexStencils stencils_;  ///< mesh_'s vertices (with refine_input, the midpoints too)
  std::vector<int> locked_;
  BasisStats stats_;
  long long build_id_ = 0;
  mutable Positions
      last_evaluated_;  ///< refine_input: all working-mesh vertices of the last evaluation
  mutable long long last_evaluated_build_ = -1;
};

}  // namespace mcf
