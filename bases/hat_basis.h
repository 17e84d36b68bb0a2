#pragma once
// The hat (piecewise-linear, P1) basis: one function per vertex, cotangent stiffness and a
// consistent (or lumped) mass matrix (docs/design.md "Conventions").

#include "bases/basis.h"
#include "bases/fixed_pattern.h"
#include "bases/surface_hierarchy.h"

#include <optional>

namespace mcf {

enum class MassKind { consistent, lumped };

class HatBasis final : public Basis {
 public:
  /// Builds the sparsity pattern (vertex adjacency incl. the diagonal) once; mass and stiffness
  /// share it, so M + δK is a value-wise sum. Matrices are assembled at the mesh's positions.
  /// With `hierarchy`, also builds the multigrid hierarchy of the input mesh
  /// (bases/surface_hierarchy.h) once; it is kept through the flow, as the mesh's connectivity is.
  /// The functions are then numbered in a bandwidth-reducing order (bases/vertex_ordering.h), not
  /// the vertices': coefficients are in that order, evaluate_vertices returns the mesh's.
  ///
  /// `output_vertices` < the mesh's vertex count: evaluate_vertices returns only the mesh's first
  /// `output_vertices` vertices (with a 1-to-4 split input, subdivide_midpoint, those are the
  /// original mesh's: the midpoints flow as functions of their own but are not output). -1: all.
  HatBasis(const TriangleMesh& mesh, MassKind mass_kind = MassKind::consistent,
           std::optional<SurfaceHierarchyOptions> hierarchy = std::nullopt,
           Eigen::Index output_vertices = -1);

  std::string name() const override { return "hat"; }
  Eigen::Index dimension() const override { return faces_.rows() ? vertices0_.rows() : 0; }
  Coefficients initial_coefficients() const override { return vertices0_; }
  void update(const Coefficients& x, bool update_mass, bool update_stiffness) override;
  SparseView mass() const override { return pattern_.view(mass_); }
  SparseView stiffness() const override { return pattern_.view(stiffness_); }
  /// The coefficients in the mesh's vertex order (the functions are renumbered with a hierarchy).
  Positions evaluate_vertices(const Coefficients& x) const override;
  std::vector<int> locked_functions() const override { return boundary_; }
  const BasisStats& stats() const override { return stats_; }
  const std::vector<SparseMatrix>* prolongations() const override {
    return hierarchy_.prolongations.empty() ? nullptr : &hierarchy_.prolongations;
  }
  const std::vector<std::vector<std::uint8_t>>* colours() const override {
    return hierarchy_.prolongations.empty() ? nullptr : &hierarchy_.colours;
  }

 private:
  Positions vertices0_;           // in the functions' order
  Triangles faces_;               // on the functions' numbers
  std::vector<int> order_;        // function k is vertex order_[k]; empty: the mesh's own order
  Eigen::Index output_vertices_;  // evaluate_vertices returns the mesh's first this many
  MassKind mass_kind_;
  FixedPattern pattern_;                  // 9 slots per face, gathered per nonzero
  std::vector<double> mass_, stiffness_;  // values on pattern_
  std::vector<Eigen::Vector3d> points_;   // the coefficients row-major (update)
  std::vector<double> face_area_;         // per face, reused every step (update)
  std::vector<double> corner_weight_;     // per face and corner: half its cotangent (update)
  std::vector<int> boundary_;
  SurfaceHierarchy hierarchy_;  // empty unless asked for
  BasisStats stats_;
};

}  // namespace mcf
