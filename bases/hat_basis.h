#pragma once
// The hat (piecewise-linear, P1) basis: one function per vertex, cotangent stiffness and a
// consistent (or lumped) mass matrix (docs/design.md "Conventions").

#include "bases/basis.h"
#include "bases/fixed_pattern.h"

namespace mcf {

enum class MassKind { consistent, lumped };

class HatBasis final : public Basis {
 public:
  /// Builds the sparsity pattern (vertex adjacency incl. the diagonal) once; mass and stiffness
  /// share it, so M + δK is a value-wise sum. Matrices are assembled at the mesh's positions.
  HatBasis(const TriangleMesh& mesh, MassKind mass_kind = MassKind::consistent);

  std::string name() const override { return "hat"; }
  Eigen::Index dimension() const override { return faces_.rows() ? vertices0_.rows() : 0; }
  Coefficients initial_coefficients() const override { return vertices0_; }
  void update(const Coefficients& x, bool update_mass, bool update_stiffness) override;
  SparseView mass() const override { return pattern_.view(mass_); }
  SparseView stiffness() const override { return pattern_.view(stiffness_); }
  Positions evaluate_vertices(const Coefficients& x) const override { return x; }
  std::vector<int> locked_functions() const override { return boundary_; }
  const BasisStats& stats() const override { return stats_; }

 private:
  Positions vertices0_;
  Triangles faces_;
  MassKind mass_kind_;
  FixedPattern pattern_;                              // 9 slots per face, gathered per nonzero
  std::vector<double> mass_, stiffness_;              // values on pattern_
  std::vector<double> local_mass_, local_stiffness_;  // per-face 3x3 blocks, reused every step
  std::vector<int> boundary_;
  BasisStats stats_;
};

/// Cotangent weights of one triangle: cot of the angle at each corner (0 for a degenerate one).
Eigen::Vector3d corner_cotangents(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                  const Eigen::Vector3d& c);

}  // namespace mcf
