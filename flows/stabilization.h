#pragma once
// The normal-gradient stabilization of a flow step (docs/octree-multigrid.md, "Stabilization").
// A step's linear solve (a M + b K) Y = R, with Y held at F on some rows, is solved for the
// increment Δ = Y - F with the band's normal-gradient matrix S (Basis::normal_gradient) added:
//   (a M + b K + ρ S) Δ = R - (a M + b K) F + ρ S Δ̂,        Δ = 0 on the held rows,
// where Δ̂ is the increment predicted from the previous step (flows/predicted_start.h, also the
// solver's start). S vanishes on
// fields constant along the surface's normals and the term acts on Δ - Δ̂ only, never on a
// position: the identity's extension has n·∇x = n ≠ 0, and a term on Y itself would pull the
// surface every step.

#include "bases/basis.h"

namespace mcf {

/// ρ = c tr(a M + b K) / tr(S): the term's diagonal is c times the system's on average, so c
/// means the same at every depth and time step. 0 when S has no positive diagonal.
double stabilization_rho(double c, double a, double b, const SparseRef& M, const SparseRef& K,
                         const SparseRef& S);

}  // namespace mcf
