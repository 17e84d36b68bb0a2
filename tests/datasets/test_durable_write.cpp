// Meshes survive a crash of the machine, not only of the process: write_mesh flushes the
// temporary file before renaming it and the folder after, as write_file_atomic does
// (core/atomic_file.h; the fsync calls are watched through tests/core/sync_log.h).

#include "../core/sync_log.h"
#include "datasets/generators.h"
#include "datasets/mesh_io.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace mcf {
namespace {

namespace fs = std::filesystem;
using test::expect_file_then_folder;
using test::syncs_of;

TEST(DurableWrite, AMeshIsSyncedBeforeItsRenameAndItsFolderAfter) {
  test::TempDir dir;
  const TriangleMesh sphere = make_icosphere(1);
  for (const std::string name : {"frame_00001.ply", "final.off", "final.obj", "final.stl"}) {
    const fs::path target = dir.file(name);
    const auto syncs =
        syncs_of([&] { write_mesh(target.string(), sphere, true, FaceCheck::trusted); });
    expect_file_then_folder(syncs, target, ".tmp");
    EXPECT_TRUE(fs::exists(target));
  }
}

}  // namespace
}  // namespace mcf
