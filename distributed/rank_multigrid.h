#pragma once
// The surface multigrid across ranks, relaxing the three coordinates together.
//
// The hierarchy is the per-partition one (distributed/rank_hierarchy.h): block-diagonal
// prolongations, so restriction and prolongation touch only a rank's own rows, and each rank forms
// the owned rows of the coarse operators A_l = P_lᵀ A_{l+1} P_l alone once it has the prolongation
// rows of its ghost vertices (exchanged once): the patterns are made at the first set_operator and
// the values refreshed on them at every one, in a fixed order. Each level keeps its owned rows as
// two blocks — the diagonal block (owned columns) and the off-diagonal block (ghost columns) —
// the finest level's being views of PETSc's matrix, and the cycle runs on them with the harness's
// own kernels:
//
// - a smoothing sweep exchanges the ghost rows of the iterate (all columns in one message, a
//   VecScatter of blocks of 4) and relaxes the owned rows by Gauss-Seidel with the ghosts fixed
//   (processor-block Gauss-Seidel, as PETSc's SOR with local sweeps), then exchanges again and
//   relaxes the interface rows (those with ghost columns) once more with their neighbours' new
//   values. Without that second pass the rows along a partition's border see values one sweep
//   old, and the cycle contracted 1.4-1.5x more slowly than in one process (0.40-0.43 a V(2,2)-
//   cycle against 0.29 on the 832k armadillo at 2 ranks); with it 0.29-0.32. The backward sweep
//   is the forward one's adjoint (the interface rows backward, then all rows backward), so a
//   cycle with forward sweeps down and backward sweeps up is symmetric, as CG's preconditioner
//   must be;
// - the coarsest level is gathered on every rank and solved there by a sparse Cholesky factor
//   (Eigen's LDLᵀ), refactorized at every set_operator;
// - V- or W-cycle (γ = 1 or 2) as in the one-process multigrid (solvers/multigrid.h).
//
// Where PETSc's PCMG solves x, y and z one after another (every level's matrix streamed three
// times), this cycle reads each matrix entry once for the three columns.
//
// Blocks: n x 4 doubles, row-major ((i, c) at 4 i + c), columns 0..2 the coordinates and column 3
// padding that stays zero. Every call is collective. Built only with PETSc (the header names
// PETSc's matrix as an opaque pointer; rank_system.cpp is its one user).

#include "distributed/rank_mesh.h"

#include <memory>
#include <string>
#include <utility>
#include <vector>

struct _p_Mat;  // PETSc's Mat is a pointer to it

namespace mcf::dist {

struct RankCycle {
  bool w_cycle = true;  ///< W (γ = 2) or V (γ = 1)
  int smooth = 5;       ///< forward sweeps down, as many backward sweeps up
};

class RankMultigrid {
 public:
  /// Builds the per-partition hierarchy and its interpolation matrices.
  RankMultigrid(const RankMesh& mesh, RankCycle cycle);
  ~RankMultigrid();
  RankMultigrid(const RankMultigrid&) = delete;
  RankMultigrid& operator=(const RankMultigrid&) = delete;

  /// Takes A (MPIAIJ over the owned rows, symmetric, the same pattern at every call; held by the
  /// caller) as the finest operator: Galerkin coarse operators, local blocks, coarsest factor.
  void set_operator(_p_Mat* A);

  /// One cycle on A X = B, X (the owned rows' block) improved in place.
  void cycle(const double* B, double* X);
  /// Y = A X on the owned rows (X's ghost rows exchanged first).
  void apply(const double* X, double* Y);

  int owned() const;
  int levels() const;
  /// Vertices of the coarsest level, over all ranks.
  long long coarsest_size() const;
  /// Bytes this rank holds: coarse operators, interpolations, the coarsest factor, buffers.
  double bytes() const;

  /// For checks against PETSc's products: level l's (0 the coarsest) owned rows and the
  /// prolongation onto level l from level l - 1 (l >= 1), as global (row, column, value); the
  /// first global row of level l on this rank and its count.
  struct Entry {
    long long row, column;
    double value;
  };
  std::vector<Entry> operator_entries(int l) const;
  std::vector<Entry> prolongation_entries(int l) const;
  std::pair<long long, int> level_rows(int l) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mcf::dist
