#pragma once
// The tracked octree basis (Chuang & Kazhdan 2011, Section 4; DESIGN.md "Tracked"): the octree,
// the clipping, the cubature and the multigrid hierarchy are built once on X_0; the test
// functions are pulled back to the initial surface, so each step only re-integrates the metric
// g = dXᵀdX of the current coefficients (the paper's SetSystemMatrices / ComputeDifferential /
// EvaluateVertex).
//
// Layout (Section 5.5 stores 25 floats per cubature point): we store per split triangle only its
// three corners in its cell's local coordinates (9 doubles). Cubature points, the 8 trilinear
// values and gradients, and an orthonormal frame of the triangle's plane are recomputed from
// them every step — cheaper than streaming them from memory, and 72 bytes per split triangle
// (24 bytes per point with the 3-point rule). Any orthonormal tangent frame of X_0(T) gives the
// same M and K (g⁻¹ and √|g| are frame-invariant), so the frame need not be stored either.

#include "bases/octree_basis.h"

#include <memory>

namespace mcf {

class TrackedOctreeBasis final : public Basis {
 public:
  explicit TrackedOctreeBasis(const TriangleMesh& mesh, OctreeOptions options = {});

  std::string name() const override { return "octree-tracked"; }
  Eigen::Index dimension() const override { return initial_->dimension(); }
  Coefficients initial_coefficients() const override { return identity_; }

  /// Re-integrates M and/or K at coefficients x: for each cubature point, dX = Σ_I x^I (η^I, μ^I),
  /// g = dXᵀdX, M_IJ += β_I β_J √|g| w, K_IJ += (η_I,μ_I) g⁻¹ (η_J,μ_J)ᵀ √|g| w. Points with a
  /// degenerate metric (pinching) contribute nothing. Lock-free: cells are visited in the tiles
  /// of OctreeSystem::tiles() (tiles of one colour share no function), each cell's 8×8 blocks
  /// summed by CellBlocks then added to the fixed pattern; the result is independent of the
  /// thread count.
  void update(const Coefficients& x, bool update_mass, bool update_stiffness) override;
  const SparseMatrix& mass() const override { return mass_; }
  const SparseMatrix& stiffness() const override { return stiffness_; }
  /// v = Σ_I β_v^I x^I with the 8 stencil weights of each original vertex on X_0.
  Positions evaluate_vertices(const Coefficients& x) const override;
  std::vector<int> locked_functions() const override { return initial_->locked_functions(); }
  const std::vector<SparseMatrix>* prolongations() const override { return initial_->prolongations(); }
  const std::vector<std::vector<std::uint8_t>>* colours() const override { return initial_->colours(); }
  const BasisStats& stats() const override { return stats_; }

  /// max over cubature points of |g - I| (entrywise) at coefficients x: 0 at x = identity up to
  /// rounding (tests; serial, not for the hot path).
  double max_metric_deviation(const Coefficients& x) const;
  /// Cubature points whose metric was degenerate in the last update.
  long long degenerate_points() const { return degenerate_points_; }
  /// Bytes of per-step pre-processed data (split-triangle corners + vertex stencils).
  std::size_t preprocessed_bytes() const;
  /// The octree, system pattern and hierarchy on X_0. Its pieces and assembled matrices were
  /// released at construction (RebuiltOctreeBasis::release_assembly): compare against a freshly
  /// built RebuiltOctreeBasis with the same options instead.
  const RebuiltOctreeBasis& initial() const { return *initial_; }

 private:
  std::unique_ptr<RebuiltOctreeBasis> initial_;  // octree, pieces, pattern, hierarchy on X_0
  const CubatureRule* rule_;
  Coefficients identity_;
  std::vector<double> local_corners_;  // 9 per piece, pieces in cell order, local coords in [0,1]
  std::vector<int> cell_start_;        // pieces of cell c: [cell_start_[c], cell_start_[c+1])
  std::vector<PointStencil> stencils_; // original vertices
  SparseMatrix mass_, stiffness_;
  BasisStats stats_;
  long long degenerate_points_ = 0;
};

}  // namespace mcf
