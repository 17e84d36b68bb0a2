#pragma once
// The multigrid's coarsest solve (header solvers/multigrid.h): x = A⁻¹ b for the columns of an
// interleaved block, from the L D Lᵀ factor of the coarsest operator, P A Pᵀ = L D Lᵀ, that
// Eigen's SimplicialLDLT computes. Eigen's own solve runs its triangular solves one right-hand
// side at a time, through a column-major copy of the block; here the forward and backward solves
// visit each entry of L once for four columns together (one vector multiply-add an entry), reading
// and writing the interleaved block directly (the layout of solvers/smoother.h: entry (i, c) at
// i*s + c, s a multiple of 4).
//
// x = Pᵀ L⁻ᵀ D⁻¹ L⁻¹ P b as Eigen computes it, but both substitutions as dot products (the
// forward one on a copy of Lᵀ, made with the factor) summed in four interleaved partial sums: no
// store per entry and no chain of dependent multiply-adds. The result equals Eigen's solve to
// rounding, not bit for bit; it does not depend on the thread count (the solve is serial).
//
// Internal to the multigrid solver (namespace multigrid_detail); not part of the solvers'
// interface.

#include "core/sparse.h"

#include <Eigen/SparseCholesky>

#include <cstddef>
#include <vector>

namespace mcf::multigrid_detail {

/// The factor in the form the solve reads it: L strictly lower (its unit diagonal implicit) and
/// its transpose, both in compressed columns, D's reciprocals, and the permutation P (row i of A
/// is row perm[i] of P A).
struct InterleavedLdlt {
  SparseMatrix lower, upper;  // L, and Lᵀ (L's rows), which the forward substitution reads
  std::vector<double> inverse_diagonal;
  std::vector<int> perm;
  int n() const { return int(perm.size()); }
};

/// Copies the factor of a successful SimplicialLDLT::factorize into f.
void copy_factor(const Eigen::SimplicialLDLT<SparseMatrix>& ldlt, InterleavedLdlt& f);

/// x = A⁻¹ b for the n x s interleaved blocks b and x (all s columns; the padding columns, zero
/// in b, come out zero). `work` is resized to n x 4 and overwritten. Serial: the substitutions are
/// chains of dependent rows, and a coarsest level is small.
void solve_interleaved(const InterleavedLdlt& f, const double* b, double* x, std::size_t s,
                       std::vector<double>& work);

}  // namespace mcf::multigrid_detail
