#pragma once
// The Galerkin product A_c = Pᵀ A P computed by PETSc (its PtAP matrix product on sequential AIJ
// matrices, one process, one thread): a second implementation of the multigrid's coarse operators
// (solvers/galerkin.h), written by others, for the tests to check those against and the
// benchmarks to time them beside (docs/benchmarks.md, "Floors"). As the multigrid does, the
// product's pattern is formed once (MatProductSymbolic) and a refresh computes only its values
// (MatProductNumeric).
//
// Without PETSc in the build the constructor throws PetscUnavailable (solvers/petsc_runtime.h);
// a failed PETSc call throws PetscFailure.

#include "core/sparse.h"

#include <memory>
#include <string>

namespace mcf {

class PetscGalerkin {
 public:
  /// A: n x n, symmetric (its compressed columns are read as PETSc's compressed rows), as every
  /// level matrix of the multigrid is; P: n x m. Copies both and forms Pᵀ A P by PETSc's
  /// `algorithm` for the product (MatProductSetAlgorithm; for sequential AIJ matrices "default",
  /// which is "scalable", "rap", which forms Pᵀ and then Pᵀ (A P), and "hypre", hypre's
  /// BoomerAMG product). PetscFailure for an algorithm PETSc does not know.
  PetscGalerkin(const SparseMatrix& A, const SparseMatrix& P,
                const std::string& algorithm = "default");
  ~PetscGalerkin();
  PetscGalerkin(const PetscGalerkin&) = delete;
  PetscGalerkin& operator=(const PetscGalerkin&) = delete;

  /// A's values replaced by `a_values` (A's nonzero count of them, in A's compressed order, on
  /// the pattern given to the constructor), then the product's values on its pattern.
  void refresh(const double* a_values);
  /// The product's values recomputed from A's present ones (what a benchmark times).
  void multiply();
  /// The product as compressed columns with sorted row indices.
  SparseMatrix product() const;

 private:
  struct Internals;
  std::unique_ptr<Internals> m_;
};

}  // namespace mcf
