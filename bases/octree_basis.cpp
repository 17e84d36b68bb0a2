#include "bases/octree_basis.h"

#include "bases/normal_gradient.h"
#include "datasets/subdivide.h"
#include "datasets/validate.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

namespace mcf {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// Finest-level functions whose support meets a boundary edge (or a boundary vertex): the corners
/// of every finest cell a boundary edge passes through. Sorted, unique.
std::vector<int> boundary_functions(const Octree& octree, const Positions& vertices,
                                    const Triangles& faces) {
  const OctreeLevel& L = octree.finest();
  const GridCube& cube = octree.cube;
  const double h = cube.cell_size();
  const int res = cube.resolution();
  std::vector<int> out;
  auto add_cell = [&](const Eigen::Vector3d& p) {
    int ijk[3];
    for (int a = 0; a < 3; ++a)
      ijk[a] = std::clamp(static_cast<int>(std::floor((p[a] - cube.origin[a]) / h)), 0, res - 1);
    for (int c = 0; c < 8; ++c) {
      const auto o = corner_offset(c);
      const int f = L.find_function(ijk[0] + o[0], ijk[1] + o[1], ijk[2] + o[2]);
      if (f >= 0) out.push_back(f);
    }
  };
  for (const auto& e : boundary_edges(faces)) {
    const Eigen::Vector3d a = vertices.row(e[0]).transpose(), b = vertices.row(e[1]).transpose();
    std::vector<double> ts = {0.0, 1.0};
    for (int ax = 0; ax < 3; ++ax) {
      const double ua = (a[ax] - cube.origin[ax]) / h, ub = (b[ax] - cube.origin[ax]) / h;
      if (ua == ub) continue;
      for (int i = static_cast<int>(std::ceil(std::min(ua, ub)));
           i <= static_cast<int>(std::floor(std::max(ua, ub))); ++i) {
        const double t = (i - ua) / (ub - ua);
        if (t > 0.0 && t < 1.0) ts.push_back(t);
      }
    }
    std::sort(ts.begin(), ts.end());
    add_cell(a);
    add_cell(b);
    for (std::size_t i = 0; i + 1 < ts.size(); ++i)
      if (ts[i + 1] > ts[i]) add_cell(a + 0.5 * (ts[i] + ts[i + 1]) * (b - a));
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace

RebuiltOctreeBasis::RebuiltOctreeBasis(const TriangleMesh& mesh, OctreeOptions options)
    : options_(options) {
  if (options_.depth < 4 || options_.depth > 10)
    throw std::invalid_argument("octree depth must be in 4..10, got " +
                                std::to_string(options_.depth));
  (void)cubature_rule(options_.cubature);  // validates
  if (mesh.num_faces() == 0) throw std::invalid_argument("RebuiltOctreeBasis: mesh has no faces");
  input_vertices_ = mesh.num_vertices();
  mesh_ = options_.refine_input ? subdivide_midpoint(mesh) : mesh;
  rebuild(mesh.vertices);
}

Eigen::Index RebuiltOctreeBasis::dimension() const {
  return octree_.finest().num_functions();
}

void RebuiltOctreeBasis::rebuild(const Positions& vertices) {
  if (vertices.rows() != input_vertices_)
    throw std::invalid_argument("RebuiltOctreeBasis::rebuild: expected " +
                                std::to_string(input_vertices_) + " vertices");
  if (options_.refine_input) {
    const Eigen::Index n = input_vertices_;
    if (last_evaluated_build_ == build_id_ && last_evaluated_.rows() == mesh_.num_vertices() &&
        last_evaluated_.topRows(n) == vertices) {
      mesh_.vertices = last_evaluated_;
    } else {
      mesh_.vertices.topRows(n) = vertices;  // midpoints of the current edges
      // Midpoint vertices from the corner sub-faces of subdivide_midpoint:
      // 4f+0 = (v0, m01, m20), 4f+1 = (v1, m12, m01), 4f+2 = (v2, m20, m12).
      for (Eigen::Index f = 0; f < mesh_.num_faces() / 4; ++f) {
        const int v0 = mesh_.faces(4 * f, 0), v1 = mesh_.faces(4 * f + 1, 0),
                  v2 = mesh_.faces(4 * f + 2, 0);
        const int e01 = mesh_.faces(4 * f, 1), e20 = mesh_.faces(4 * f, 2),
                  e12 = mesh_.faces(4 * f + 1, 1);
        mesh_.vertices.row(e01) = 0.5 * (vertices.row(v0) + vertices.row(v1));
        mesh_.vertices.row(e12) = 0.5 * (vertices.row(v1) + vertices.row(v2));
        mesh_.vertices.row(e20) = 0.5 * (vertices.row(v2) + vertices.row(v0));
      }
    }
  } else {
    mesh_.vertices = vertices;
  }
  ++build_id_;
  stats_ = BasisStats{};

  auto t0 = Clock::now();
  const GridCube cube = choose_cube(mesh_, options_.depth, options_.cube);
  stats_.cube_origin = {cube.origin.x(), cube.origin.y(), cube.origin.z()};
  stats_.cube_side = cube.side;
  double t_octree = seconds_since(t0);

  t0 = Clock::now();
  pieces_ = clip_mesh(mesh_.vertices, mesh_.faces, cube);
  stats_.setup_seconds["clip"] = seconds_since(t0);

  t0 = Clock::now();
  system_.reset();
  octree_ = build_octree(cube, pieces_, options_.coarsest_depth);
  piece_cells_ = locate_pieces(octree_, pieces_);
  stencils_ = vertex_stencils(octree_, mesh_.vertices, mesh_.faces);
  locked_ = boundary_functions(octree_, mesh_.vertices, mesh_.faces);
  stats_.setup_seconds["octree"] = t_octree + seconds_since(t0);

  t0 = Clock::now();
  system_ =
      std::make_unique<OctreeSystem>(octree_, octree_.num_levels() - 1, pieces_, piece_cells_);
  system_->assemble(cubature_rule(options_.cubature), mass_, stiffness_);
  stats_.setup_seconds["integrate"] = seconds_since(t0);

  if (options_.normal_gradient) {
    t0 = Clock::now();
    normal_gradient_ =
        assemble_normal_gradient(*system_, octree_, cell_normals(octree_, pieces_, piece_cells_));
    stats_.setup_seconds["normal_gradient"] = seconds_since(t0);
  } else {
    std::vector<double>().swap(normal_gradient_);
  }

  t0 = Clock::now();
  prolongations_ = build_prolongations(octree_);
  colours_ = build_colours(octree_);
  stats_.setup_seconds["hierarchy"] = seconds_since(t0);

  stats_.dimension = dimension();
  stats_.split_triangles = static_cast<long long>(pieces_.size());
  stats_.cubature_points = stats_.split_triangles * cubature_rule(options_.cubature).size();
  stats_.levels = octree_.num_levels();
  // Rebuilt: nothing is stored per cubature point beyond the piece (3 corners, cell, triangle).
  stats_.bytes_per_cubature_point = static_cast<double>(sizeof(ClippedTriangle) + sizeof(int)) /
                                    cubature_rule(options_.cubature).size();
}

void RebuiltOctreeBasis::release_assembly(std::vector<double>& mass, std::vector<double>& stiffness,
                                          std::vector<double>& normal_gradient) {
  mass.swap(mass_);
  stiffness.swap(stiffness_);
  normal_gradient.swap(normal_gradient_);
  std::vector<double>().swap(mass_);
  std::vector<double>().swap(stiffness_);
  std::vector<double>().swap(normal_gradient_);
  // swap with empty vectors: clear() alone keeps the capacity (the pieces are the largest array).
  std::vector<ClippedTriangle>().swap(pieces_);
  std::vector<int>().swap(piece_cells_);
  system_->release_pieces();
  // The tracked basis keeps the stencils of the input's vertices itself.
  stencils_ = VertexStencils{};
}

namespace {
// What mass() and stiffness() show before assembly and after release_assembly.
SparseView values_view(const OctreeSystem* system, const std::vector<double>& values) {
  if (system && static_cast<Eigen::Index>(values.size()) == system->non_zeros())
    return system->view(values);
  return view_of(std::vector<int>{}, std::vector<int>{}, std::vector<double>{});
}
}  // namespace

SparseView RebuiltOctreeBasis::mass() const {
  return values_view(system_.get(), mass_);
}
SparseView RebuiltOctreeBasis::stiffness() const {
  return values_view(system_.get(), stiffness_);
}
SparseView RebuiltOctreeBasis::normal_gradient() const {
  return values_view(system_.get(), normal_gradient_);
}

Coefficients RebuiltOctreeBasis::initial_coefficients() const {
  return octree_.function_positions(octree_.num_levels() - 1);
}

void RebuiltOctreeBasis::update(const Coefficients& x, bool, bool) {
  if (x.rows() != dimension())
    throw std::invalid_argument(
        "RebuiltOctreeBasis::update: coefficient count does not match the dimension");
}

void RebuiltOctreeBasis::reframe(const Eigen::RowVector3d& centroid, double scale) {
  // The same expression the flow applies to the vertices, so the top rows stay bitwise equal to
  // the vertices rebuild() will be given.
  if (options_.refine_input && last_evaluated_build_ == build_id_)
    last_evaluated_ = (last_evaluated_.rowwise() - centroid) * scale;
}

Positions RebuiltOctreeBasis::evaluate_vertices(const Coefficients& x) const {
  if (x.rows() != dimension())
    throw std::invalid_argument(
        "RebuiltOctreeBasis::evaluate_vertices: coefficient count does not match the dimension");
  if (system_->pieces_released())
    throw std::logic_error(
        "RebuiltOctreeBasis::evaluate_vertices: the stencils were released (release_assembly)");
  Positions all = mcf::evaluate_vertices(stencils_, x);
  if (!options_.refine_input) return all;
  last_evaluated_ = all;
  last_evaluated_build_ = build_id_;
  return all.topRows(input_vertices_);
}

}  // namespace mcf
