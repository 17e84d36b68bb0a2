#pragma once
// Small helpers shared by the datasets tests.

#include "datasets/mesh.h"

#include <Eigen/Geometry>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>

namespace mcf::test {

/// A fresh folder under the system temp dir, removed at the end of the test.
class TempDir {
 public:
  TempDir() {
    std::random_device rd;
    path_ = std::filesystem::temp_directory_path() / ("mcf_datasets_test_" + std::to_string(rd()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(file(name), std::ios::binary) << text;
    return file(name);
  }

 private:
  std::filesystem::path path_;
};

/// Signed volume enclosed by a closed mesh: positive when faces are oriented outward.
inline double signed_volume(const TriangleMesh& m) {
  double v = 0;
  for (Eigen::Index f = 0; f < m.num_faces(); ++f) {
    const Eigen::Vector3d a = m.vertices.row(m.faces(f, 0)), b = m.vertices.row(m.faces(f, 1)),
                          c = m.vertices.row(m.faces(f, 2));
    v += a.dot(b.cross(c)) / 6.0;
  }
  return v;
}

/// Two triangles are the same face when they are equal up to a cyclic rotation.
inline bool same_face(const Eigen::RowVector3i& a, const Eigen::RowVector3i& b) {
  for (int r = 0; r < 3; ++r)
    if (a(0) == b(r) && a(1) == b((r + 1) % 3) && a(2) == b((r + 2) % 3)) return true;
  return false;
}

}  // namespace mcf::test
