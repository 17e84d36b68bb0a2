#include "distributed/rank_hierarchy.h"

#include "bases/surface_hierarchy.h"
#include "distributed/comm.h"

#include <algorithm>

namespace mcf::dist {

RankHierarchy build_rank_hierarchy(const RankMesh& mesh, int coarsest_size) {
  // The triangles of the owned surface: all three corners owned (local numbers below `owned`).
  std::vector<int> kept;
  for (Eigen::Index f = 0; f < mesh.faces.rows(); ++f)
    if (mesh.faces(f, 0) < mesh.owned && mesh.faces(f, 1) < mesh.owned &&
        mesh.faces(f, 2) < mesh.owned)
      kept.push_back(int(f));
  Triangles faces(Eigen::Index(kept.size()), 3);
  for (std::size_t k = 0; k < kept.size(); ++k)
    faces.row(Eigen::Index(k)) = mesh.faces.row(kept[k]);
  SurfaceHierarchyOptions options;
  options.coarsest_size = std::max(coarsest_size, 1);
  SurfaceHierarchy h = build_surface_hierarchy(mesh.vertices.topRows(mesh.owned), faces, options);
  // The finest levels every rank has.
  const int mine = h.levels();
  const int levels = int(-max_over_ranks(-double(mine)));
  RankHierarchy out;
  const std::size_t drop = std::size_t(mine - levels);
  out.prolongations.assign(std::make_move_iterator(h.prolongations.begin() + std::ptrdiff_t(drop)),
                           std::make_move_iterator(h.prolongations.end()));
  return out;
}

}  // namespace mcf::dist
