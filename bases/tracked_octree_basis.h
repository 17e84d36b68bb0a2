#pragma once
// The tracked octree basis (Chuang & Kazhdan 2011, Section 4; docs/design.md "The octree basis",
// tracked): the octree, the clipping, the cubature and the multigrid hierarchy are built once on
// X_0; the test functions are pulled back to the initial surface, so each step only re-integrates
// the metric g = dXᵀdX of the current coefficients (the paper's SetSystemMatrices /
// ComputeDifferential / EvaluateVertex).
//
// Layout (Section 5.5 stores 25 floats per cubature point): we store per split triangle only its
// corners in its cell's local coordinates. Cubature points, the 8 trilinear values and
// gradients, and an orthonormal frame of the triangle's plane are recomputed from them every
// step — cheaper than streaming them from memory. Any orthonormal tangent frame of X_0(T) gives
// the same M and K (g⁻¹ and √|g| are frame-invariant), so the frame need not be stored either.
// The clipper fan-triangulates each cell's polygon, (p0, p_k, p_k+1), and a cell's pieces keep
// that order, so the corners are stored as fans: a piece that continues the previous one's fan
// (the same p0, its p1 the previous p2, bitwise) stores only its new corner (3 doubles instead of
// 9) and a flag. The corners read are the very same doubles, so M and K are bitwise those of
// storing 9 per piece (bytes per cubature point: docs/octree-multigrid.md "Assembly").

#include "bases/octree_basis.h"

#include <cstdint>
#include <memory>

namespace mcf {

class TrackedOctreeBasis final : public Basis {
 public:
  explicit TrackedOctreeBasis(const TriangleMesh& mesh, OctreeOptions options = {});

  std::string name() const override { return "octree-tracked"; }
  Eigen::Index dimension() const override { return initial_->dimension(); }
  /// The identity embedding: the finest functions' node positions (computed on each call rather
  /// than kept beside the coefficients: the flow asks once).
  Coefficients initial_coefficients() const override { return initial_->initial_coefficients(); }

  /// Re-integrates M and/or K at coefficients x: for each cubature point, dX = Σ_I x^I (η^I, μ^I),
  /// g = dXᵀdX, M_IJ += β_I β_J √|g| w, K_IJ += (η_I,μ_I) g⁻¹ (η_J,μ_J)ᵀ √|g| w. Points with a
  /// degenerate metric (pinching) contribute nothing. Lock-free: cells are visited in the tiles
  /// of OctreeSystem::tiles() (tiles of one colour share no function), each cell's 8×8 blocks
  /// summed by CellBlocks then added to the fixed pattern; the result is independent of the
  /// thread count.
  void update(const Coefficients& x, bool update_mass, bool update_stiffness) override;
  /// On the initial basis's system pattern (OctreeSystem::view): one copy of the index arrays.
  SparseView mass() const override { return initial_->system().view(mass_); }
  SparseView stiffness() const override { return initial_->system().view(stiffness_); }
  /// With options.normal_gradient: S of X_0's band, assembled once (it never changes: the
  /// functions are pulled back to X_0, and so is the stabilization).
  SparseView normal_gradient() const override;
  /// v = Σ_I β_v^I x^I with the 8 stencil weights of each original vertex on X_0.
  Positions evaluate_vertices(const Coefficients& x) const override;
  std::vector<int> locked_functions() const override { return initial_->locked_functions(); }
  const std::vector<SparseMatrix>* prolongations() const override {
    return initial_->prolongations();
  }
  const std::vector<std::vector<std::uint8_t>>* colours() const override {
    return initial_->colours();
  }
  const BasisStats& stats() const override { return stats_; }

  /// max over cubature points of |g - I| (entrywise) at coefficients x: 0 at x = identity up to
  /// rounding (tests; serial, not for the hot path).
  double max_metric_deviation(const Coefficients& x) const;
  /// Cubature points whose metric was degenerate in the last update.
  long long degenerate_points() const { return degenerate_points_; }
  /// Bytes of per-step pre-processed data (the fans' corners, their flags and per-cell starts).
  std::size_t preprocessed_bytes() const;
  /// Split triangles stored as the continuation of a fan (3 doubles instead of 9); tests, reports.
  long long fan_continuations() const;
  /// The corners of cell c's pieces in cell-local coordinates, 9 per piece in piece order, decoded
  /// from the fans (tests: they must equal the pieces' own, bitwise).
  std::vector<double> cell_local_corners(int c) const;
  /// The octree, system pattern and hierarchy on X_0. Its pieces and assembled matrices were
  /// released at construction (RebuiltOctreeBasis::release_assembly): compare against a freshly
  /// built RebuiltOctreeBasis with the same options instead.
  const RebuiltOctreeBasis& initial() const { return *initial_; }

 private:
  /// Pieces of cell c: [cell_start()[c], cell_start()[c+1]), the system's own (it stays after
  /// release_assembly).
  const std::vector<int>& cell_start() const { return initial_->system().cell_start(); }

  std::unique_ptr<RebuiltOctreeBasis> initial_;  // octree, pieces, pattern, hierarchy on X_0
  const CubatureRule* rule_;
  std::vector<double> fan_points_;       // fans' corners, cells in order, local coords in [0,1]
  std::vector<std::uint8_t> continues_;  // per piece (cell order): 1 = continues the previous fan
  std::vector<int>
      point_start_;  // cell c's fan points: [point_start_[c], point_start_[c+1]), 3 doubles each
  VertexStencils stencils_;               // original vertices
  std::vector<double> mass_, stiffness_;  // values on initial_->system()'s pattern
  std::vector<double> normal_gradient_;   // idem, X_0's band (options.normal_gradient)
  BasisStats stats_;
  long long degenerate_points_ = 0;
};

}  // namespace mcf
