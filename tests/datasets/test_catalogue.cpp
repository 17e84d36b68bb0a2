#include "datasets/catalogue.h"
#include "datasets/mesh_error.h"
#include "datasets/mesh_io.h"
#include "datasets/mesh_spec.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <string>

namespace mcf {
namespace {

bool archive_present() {
  const char* c = std::getenv("MCFBENCH_CACHE");
  const char* home = std::getenv("HOME");
  const std::filesystem::path cache =
      c && *c ? std::filesystem::path(c)
              : std::filesystem::path(home ? home : "/tmp") / ".cache" / "mcfbench";
  return std::filesystem::exists("/usr/share/doc/libcgal-dev/data.tar.gz") ||
         std::filesystem::exists(cache / "cgal-demo/usr/share/doc/libcgal-dev/data.tar.gz");
}

#define REQUIRE_ARCHIVE() \
  if (!archive_present()) GTEST_SKIP() << "libcgal-demo data.tar.gz absent: run scripts/setup.sh"

void expect_in_unit_cube(const TriangleMesh& m) {
  const Eigen::RowVector3d lo = m.vertices.colwise().minCoeff(),
                           hi = m.vertices.colwise().maxCoeff();
  EXPECT_GE(lo.minCoeff(), -1e-12);
  EXPECT_LE(hi.maxCoeff(), 1 + 1e-12);
  EXPECT_NEAR((hi - lo).maxCoeff(), 1.0, 1e-12);  // fills the cube along one axis
  EXPECT_NEAR(((lo + hi) / 2 - Eigen::RowVector3d::Constant(0.5)).norm(), 0.0, 1e-12);  // centred
}

TEST(Catalogue, ListsThePaperStandIns) {
  const auto models = catalogue_models();
  for (const char* name :
       {"armadillo", "bunny00", "refined_elephant", "mannequin-devil", "knot1", "knot2", "man"})
    EXPECT_NE(std::find(models.begin(), models.end(), name), models.end()) << name;
}

TEST(Catalogue, LoadsArmadilloAndBunny) {
  REQUIRE_ARCHIVE();
  for (const char* name : {"armadillo", "bunny00"}) {
    const std::string path = catalogue_path(name);
    EXPECT_TRUE(std::filesystem::is_regular_file(path)) << path;
    EXPECT_EQ(catalogue_path(name), path);  // cached: same file again
    const MeshSource src = load_mesh_spec(std::string("cgal:") + name);
    EXPECT_EQ(src.kind, "cgal");
    EXPECT_FALSE(src.analytic);
    EXPECT_FALSE(src.sphere_radius.has_value());
    EXPECT_GT(src.mesh.num_vertices(), 10000);
    EXPECT_EQ(src.report.faces, src.mesh.num_faces());
    expect_in_unit_cube(src.mesh);
  }
}

TEST(Catalogue, ExtractsIntoAFreshCache) {
  REQUIRE_ARCHIVE();
  test::TempDir dir;
  const char* old = std::getenv("MCFBENCH_CACHE");
  const char* home = std::getenv("HOME");
  // The archive found through the old cache location must keep being found: point the new
  // cache's cgal-demo at it.
  const std::filesystem::path old_cache =
      old && *old ? std::filesystem::path(old)
                  : std::filesystem::path(home ? home : "/tmp") / ".cache" / "mcfbench";
  if (std::filesystem::exists(old_cache / "cgal-demo"))
    std::filesystem::create_directory_symlink(old_cache / "cgal-demo", dir.file("cgal-demo"));
  const std::string saved = old ? old : "";
  setenv("MCFBENCH_CACHE", dir.file("").c_str(), 1);
  std::string path;
  EXPECT_NO_THROW(path = catalogue_path("knot1"));
  if (old)
    setenv("MCFBENCH_CACHE", saved.c_str(), 1);
  else
    unsetenv("MCFBENCH_CACHE");
  EXPECT_EQ(path, dir.file("models/knot1.off"));
  // Only the model is left behind, no temporary extraction folder.
  int entries = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir.file("models")))
    ++entries;
  EXPECT_EQ(entries, 1);
}

TEST(Catalogue, MissingArchiveSaysRunSetup) {
  test::TempDir dir;
  if (std::filesystem::exists("/usr/share/doc/libcgal-dev/data.tar.gz"))
    GTEST_SKIP() << "system archive present";
  const char* old = std::getenv("MCFBENCH_CACHE");
  const std::string saved = old ? old : "";
  setenv("MCFBENCH_CACHE", dir.file("").c_str(), 1);
  try {
    catalogue_path("armadillo");
    ADD_FAILURE() << "no error without an archive";
  } catch (const MeshError& e) {
    EXPECT_NE(std::string(e.what()).find("scripts/setup.sh"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("armadillo"), std::string::npos) << e.what();
  }
  if (old)
    setenv("MCFBENCH_CACHE", saved.c_str(), 1);
  else
    unsetenv("MCFBENCH_CACHE");
}

TEST(Catalogue, UnknownModel) {
  EXPECT_THROW(catalogue_path("no_such_model"), MeshError);
}

// Every catalogued model must load and validate: the list promises usable meshes.
TEST(Catalogue, EveryModelValidates) {
  REQUIRE_ARCHIVE();
  for (const auto& name : catalogue_models()) {
    try {
      const MeshSource src = load_mesh_spec("cgal:" + name);
      EXPECT_GT(src.report.faces, 0) << name;
    } catch (const MeshError& e) {
      ADD_FAILURE() << e.what();
    }
  }
}

TEST(Catalogue, ArmadilloAt832kFacesIsFast) {
  REQUIRE_ARCHIVE();
  const auto t0 = std::chrono::steady_clock::now();
  const MeshSource src = load_mesh_spec("cgal:armadillo@faces=832000");
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_GE(src.mesh.num_faces(), 832000);
  EXPECT_EQ(src.report.faces, src.mesh.num_faces());
  EXPECT_LT(s, 10.0) << "load + subdivide + validate took " << s << " s";
}

}  // namespace
}  // namespace mcf
