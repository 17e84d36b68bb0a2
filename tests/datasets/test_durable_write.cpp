// Results survive a crash of the machine, not only of the process: write_file_atomic and
// write_mesh flush the temporary file before renaming it and the folder after (datasets/
// atomic_file.h). A crash cannot be staged in a test, so this test watches the calls instead: it
// interposes fsync for this test executable (a definition here takes precedence over the C
// library's for every object linked into it) and records which path each call flushed.

#include "datasets/atomic_file.h"
#include "datasets/generators.h"
#include "datasets/mesh_io.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <sys/syscall.h>
#include <unistd.h>
#include <climits>
#include <filesystem>
#include <string>
#include <vector>

namespace {

struct SyncLog {
  bool on = false;
  std::vector<std::string> paths;  // what each fsync flushed, in call order
} sync_log;

}  // namespace

extern "C" int fsync(int fd) {
  if (sync_log.on) {
    char buf[PATH_MAX];
    const std::string link = "/proc/self/fd/" + std::to_string(fd);
    const ssize_t n = ::readlink(link.c_str(), buf, sizeof buf);
    sync_log.paths.push_back(n > 0 ? std::string(buf, std::size_t(n)) : "?");
  }
  return int(::syscall(SYS_fsync, fd));
}

namespace mcf {
namespace {

namespace fs = std::filesystem;

/// Records the fsync calls of `write`; returns them.
template <class Write>
std::vector<std::string> syncs_of(Write&& write) {
  sync_log = {};
  sync_log.on = true;
  write();
  sync_log.on = false;
  return sync_log.paths;
}

/// The log's paths as they were at call time; a synced temporary file was renamed since.
void expect_file_then_folder(const std::vector<std::string>& syncs, const fs::path& target,
                             const std::string& temporary_marker) {
  ASSERT_EQ(syncs.size(), 2u) << "expected the temporary file, then the folder, to be synced";
  const fs::path file(syncs[0]);
  EXPECT_EQ(fs::canonical(file.parent_path()), fs::canonical(target.parent_path()));
  EXPECT_NE(file.filename().string().find(temporary_marker), std::string::npos)
      << syncs[0] << ": the temporary file is synced before it is renamed";
  EXPECT_EQ(fs::canonical(syncs[1]), fs::canonical(target.parent_path())) << "then the folder";
}

TEST(DurableWrite, AResultIsSyncedBeforeItsRenameAndItsFolderAfter) {
  test::TempDir dir;
  const fs::path target = dir.file("cell.json");
  const auto syncs =
      syncs_of([&] { write_file_atomic(target.string(), "{\"status\": \"ok\"}\n"); });
  expect_file_then_folder(syncs, target, "cell.json.tmp.");
  // Overwriting an existing result syncs the same way (rename over a file orders nothing either).
  const auto again = syncs_of([&] { write_file_atomic(target.string(), "{}\n"); });
  expect_file_then_folder(again, target, "cell.json.tmp.");
}

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

TEST(DurableWrite, SyncingAMissingFileNamesIt) {
  test::TempDir dir;
  try {
    sync_to_disk(dir.file("gone.json"));
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("gone.json: cannot open to sync"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace mcf
