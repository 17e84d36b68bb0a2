#pragma once
// What the rows' memory models read and return (config/memory_estimate.h adds them up): a basis
// row sizes the mesh's and its own share and describes its system matrix; a solver row sizes what
// it adds to that matrix. Every figure is in bytes.

#include <cmath>

namespace mcf {

/// The sizes an estimate needs. `area_over_side2` < 0: the octree's size is not known yet (a
/// spec that has not been built), so the estimate leaves the octree out and is a lower bound.
struct FlowSizes {
  double vertices = 0, faces = 0;
  double area_over_side2 = -1;  ///< surface area / (octree cube side)^2, the octree's scale
  bool exact = false;           ///< from the mesh itself, not from a spec's sizes
};

/// A basis row's share of a flow's memory, and its unknowns.
struct BasisMemory {
  double mesh_bytes = 0;     ///< grows with the input mesh (per vertex)
  double basis_bytes = 0;    ///< grows with the basis's functions (0 where they are the vertices)
  double dimension = 0;      ///< unknowns
  bool lower_bound = false;  ///< the basis's size was unknown: its share is left out
};

/// The system matrix of a basis, as a solver's memory model reads it.
struct SystemFigures {
  double dimension = 0;         ///< unknowns
  double nonzeros_per_row = 0;  ///< of the system matrix
  /// A supernodal Cholesky factor's bytes per unknown on this basis's graph (a fit).
  double factor_bytes_per_unknown = 0;
  /// A geometric multigrid's levels and buffers per unknown beyond what the basis holds (a fit;
  /// 0 where the basis's own hierarchy is counted in its share).
  double hierarchy_bytes_per_unknown = 0;
};

/// The finest octree level's function count expected for a surface: about 3 A / h^2 for area A
/// and finest cell size h = side / 2^depth (each function's support meets the surface in about
/// a third of the area of its 2h x 2h x 2h box: measured 2.84-3.02 on the armadillo, the
/// elephant and spheres at depths 6 to 9).
inline double estimated_octree_dimension(double area_over_side2, int depth) {
  constexpr double functions_per_area = 3.0;
  return functions_per_area * area_over_side2 * std::ldexp(1.0, 2 * depth);
}

}  // namespace mcf
