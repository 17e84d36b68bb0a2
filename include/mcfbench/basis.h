#pragma once
// A finite-element basis on a mesh and its operators: mass M_IJ = ∫ B_I B_J dA and stiffness
// K_IJ = ∫ ∇B_I · ∇B_J dA (positive semi-definite; papers that write the Laplacian L mean -K),
// at coefficients x that describe the embedding X = Σ_I x^I B_I (docs/design.md#conventions).

#include "mcfbench/export.h"
#include "mcfbench/mesh.h"
#include "mcfbench/types.h"

#include <memory>
#include <string>
#include <vector>

namespace mcfbench {

class MCFBENCH_API Basis {
 public:
  /// Builds the basis the options name on the mesh and integrates M and K at its initial
  /// coefficients.
  /// Inputs:
  ///   mesh     a loaded mesh (its copy is kept)
  ///   options  "basis" (hat | octree), "mass" (hat: consistent | lumped), the octree's "depth",
  ///            "cubature", "cube", "tracking", "refine-input", "stabilization"; the other keys
  ///            of a flow are read and checked too
  /// Throws InputError naming the option on a bad one (an octree over a mesh outside its cube).
  Basis(const Mesh& mesh, const Options& options = {});
  ~Basis();
  Basis(Basis&&) noexcept;
  Basis& operator=(Basis&&) noexcept;

  std::string name() const;
  /// Number of functions: the rows of M and K (the hat basis: the mesh's vertices).
  Eigen::Index dimension() const;
  /// dimension x 3 coefficients that reproduce the mesh (the hat basis: its vertices).
  DenseMatrix initial_coefficients() const;
  /// Re-integrates M and K at coefficients x (dimension x 3) of the same functions. The rebuilt
  /// octree, whose functions change with the surface, refuses (InputError).
  void update(const DenseMatrix& x);
  /// dimension x dimension, symmetric (both triangles stored), at the last coefficients; the
  /// references stay valid until the next update().
  const SparseMatrix& mass() const;
  const SparseMatrix& stiffness() const;
  /// n x 3 positions of the mesh's vertices under coefficients x (dimension x 3).
  Vertices evaluate_vertices(const DenseMatrix& x) const;
  /// Functions a flow holds at their value: those of an open surface's boundary (sorted).
  std::vector<int> locked_functions() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// M and K of the mesh's initial embedding.
struct Operators {
  SparseMatrix M;  ///< mass, dimension x dimension
  SparseMatrix K;  ///< stiffness, dimension x dimension
};

/// Basis(mesh, options)'s M and K, as copies the caller owns.
MCFBENCH_API Operators matrices(const Mesh& mesh, const Options& options = {});

}  // namespace mcfbench
