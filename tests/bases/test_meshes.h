#pragma once
// Small local mesh builders for the bases tests (the datasets generators live on another branch).

#include "datasets/mesh.h"

#include <Eigen/Geometry>

#include <cmath>
#include <map>
#include <random>
#include <utility>
#include <vector>

namespace {

/// Icosahedron subdivided `level` times (1-to-4, projected to the sphere). level 5: 10242
/// vertices, level 6: 40962.
inline mcf::TriangleMesh test_icosphere(int level, double radius = 1.0,
                                        const Eigen::Vector3d& center = Eigen::Vector3d::Zero()) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> V = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                                    {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                                    {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<std::array<int, 3>> F = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (auto& v : V) v.normalize();
  for (int l = 0; l < level; ++l) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      V.push_back((V[static_cast<std::size_t>(a)] + V[static_cast<std::size_t>(b)]).normalized());
      const int id = static_cast<int>(V.size()) - 1;
      mid[key] = id;
      return id;
    };
    std::vector<std::array<int, 3>> G;
    for (const auto& f : F) {
      const int a = midpoint(f[0], f[1]), b = midpoint(f[1], f[2]), c = midpoint(f[2], f[0]);
      G.push_back({f[0], a, c});
      G.push_back({f[1], b, a});
      G.push_back({f[2], c, b});
      G.push_back({a, b, c});
    }
    F = std::move(G);
  }
  mcf::TriangleMesh m;
  m.vertices.resize(static_cast<Eigen::Index>(V.size()), 3);
  for (std::size_t i = 0; i < V.size(); ++i)
    m.vertices.row(static_cast<Eigen::Index>(i)) = (center + radius * V[i]).transpose();
  m.faces.resize(static_cast<Eigen::Index>(F.size()), 3);
  for (std::size_t i = 0; i < F.size(); ++i)
    m.faces.row(static_cast<Eigen::Index>(i)) << F[i][0], F[i][1], F[i][2];
  return m;
}

inline Eigen::Matrix3d test_random_rotation(unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n;
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  return q.normalized().toRotationMatrix();
}

inline double test_face_area(const mcf::TriangleMesh& m, Eigen::Index f) {
  const Eigen::Vector3d a = m.vertices.row(m.faces(f, 0)).transpose();
  const Eigen::Vector3d b = m.vertices.row(m.faces(f, 1)).transpose();
  const Eigen::Vector3d c = m.vertices.row(m.faces(f, 2)).transpose();
  return 0.5 * (b - a).cross(c - a).norm();
}

inline double test_mesh_area(const mcf::TriangleMesh& m) {
  double s = 0.0;
  for (Eigen::Index f = 0; f < m.num_faces(); ++f) s += test_face_area(m, f);
  return s;
}

/// Uniformly random points on random faces.
inline mcf::Positions test_surface_points(const mcf::TriangleMesh& m, int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<Eigen::Index> face(0, m.num_faces() - 1);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  mcf::Positions P(count, 3);
  for (int i = 0; i < count; ++i) {
    const Eigen::Index f = face(rng);
    double s = u(rng), t = u(rng);
    if (s + t > 1.0) {
      s = 1.0 - s;
      t = 1.0 - t;
    }
    P.row(i) = (1.0 - s - t) * m.vertices.row(m.faces(f, 0)) + s * m.vertices.row(m.faces(f, 1)) +
               t * m.vertices.row(m.faces(f, 2));
  }
  return P;
}

}  // namespace
