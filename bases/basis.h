#pragma once
// A finite-element basis turns a mesh (and the current coefficients) into a mass matrix, a
// stiffness matrix and optionally a multigrid hierarchy (docs/design.md "Layers", "Conventions").
//   mass      M_IJ = ∫ B_I B_J dA          stiffness K_IJ = ∫ ∇B_I · ∇B_J dA  (K is PSD)
// Coefficients x (dimension x 3) describe the embedding X = Σ_I x^I B_I; vertices are recovered
// with evaluate_vertices.

#include "core/sparse.h"
#include "datasets/mesh.h"

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace mcf {

using Coefficients = Eigen::Matrix<double, Eigen::Dynamic, 3>;

/// What a basis reports about its construction (result.json "system").
struct BasisStats {
  long long dimension = 0;
  long long split_triangles = 0;  ///< clipped pieces (octree); faces (hat)
  long long cubature_points = 0;
  int levels = 1;
  double bytes_per_cubature_point = 0.0;
  std::map<std::string, double> setup_seconds;  ///< phase -> seconds of the last (re)build
  /// Octree bases: the grid's cube on X_0 (octree.cube "auto" picks the unit cube or a tight
  /// one, which result.json could not tell apart); cube_side 0 for the hat basis.
  std::array<double, 3> cube_origin{};
  double cube_side = 0.0;
};

class Basis {
 public:
  virtual ~Basis() = default;
  virtual std::string name() const = 0;

  /// Number of functions (rows of M and K).
  virtual Eigen::Index dimension() const = 0;

  /// True when the basis is rebuilt from the current mesh every step (the rebuilt octree); the
  /// flow then calls rebuild(vertices) before each step and restarts from initial_coefficients().
  virtual bool rebuilds_every_step() const { return false; }
  virtual void rebuild(const Positions& /*vertices*/) {}
  /// The flow moved the surface it evaluated last to a new frame, x -> (x - centroid) * scale
  /// (unit-area normalisation). A basis that keeps positions of its own beside the coefficients
  /// moves them alike (the rebuilt octree's refined midpoints); the others have nothing to do.
  virtual void reframe(const Eigen::RowVector3d& /*centroid*/, double /*scale*/) {}

  /// Coefficients that reproduce the current (initial) embedding: vertex positions for the hat
  /// basis, x_0^I = c_I (grid-vertex positions) for the octree.
  virtual Coefficients initial_coefficients() const = 0;

  /// Re-integrates the requested matrices at the embedding given by x. The sparsity pattern is
  /// fixed between rebuilds, so solvers can reuse their symbolic work.
  virtual void update(const Coefficients& x, bool update_mass, bool update_stiffness) = 0;
  /// Views valid until the next update() or rebuild() (or the basis's end); copy one into a
  /// SparseMatrix to keep it.
  virtual SparseView mass() const = 0;
  virtual SparseView stiffness() const = 0;

  /// Vertex positions of the original mesh's vertices under coefficients x.
  virtual Positions evaluate_vertices(const Coefficients& x) const = 0;

  /// Functions held at their current value (open boundaries: docs/design.md "Conventions").
  virtual std::vector<int> locked_functions() const = 0;

  /// The band's normal-gradient matrix S_IJ = ∫ (n·∇B_I)(n·∇B_J) dV (bases/normal_gradient.h) on
  /// the pattern of M and K, which the flows add, weighted, to the system of an increment
  /// (docs/octree-multigrid.md, "Stabilization"). Empty (0 x 0) for a basis that has none (the hat
  /// basis) or was not asked to assemble it; like mass(), valid until the next rebuild().
  virtual SparseView normal_gradient() const {
    return view_of(std::vector<int>{}, std::vector<int>{}, std::vector<double>{});  // 0 x 0
  }

  /// Multigrid hierarchy (coarsest level first); empty for bases without one.
  virtual const std::vector<SparseMatrix>* prolongations() const { return nullptr; }
  virtual const std::vector<std::vector<std::uint8_t>>* colours() const { return nullptr; }

  virtual const BasisStats& stats() const = 0;
};

}  // namespace mcf
