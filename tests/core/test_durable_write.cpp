// Results survive a crash of the machine, not only of the process: write_file_atomic flushes the
// temporary file before renaming it and the folder after (core/atomic_file.h).

#include "core/atomic_file.h"
#include "sync_log.h"
#include "temp_dir.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <stdexcept>
#include <string>

namespace mcf {
namespace {

namespace fs = std::filesystem;
using test::expect_file_then_folder;
using test::syncs_of;

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
