// write_file_atomic: a temporary file a killed writer left beside its target (TARGET.tmp.PID of
// a process that is gone) is removed by the next write of that target; those of live processes
// and of other targets stay.

#include "core/atomic_file.h"
#include "temp_dir.h"

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace mcf {
namespace {

namespace fs = std::filesystem;

/// The id of a process that has exited and been reaped.
pid_t dead_pid() {
  const pid_t pid = ::fork();
  if (pid == 0) _exit(0);
  int status = 0;
  ::waitpid(pid, &status, 0);
  return pid;
}

std::string read(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(AtomicFile, NextWriteRemovesTheTemporaryFilesOfDeadWritersOfThatFileOnly) {
  test::TempDir dir;
  const std::string target = dir.file("cell.json");
  const pid_t dead = dead_pid();
  ASSERT_GT(dead, 0);
  const std::string stale = target + ".tmp." + std::to_string(dead);
  const std::string live = target + ".tmp." + std::to_string(::getppid());  // our parent is alive
  const std::string other = dir.file("other.json.tmp." + std::to_string(dead));
  const std::string not_pid = target + ".tmp.notes";
  for (const std::string& f : {stale, live, other, not_pid})
    dir.write(fs::path(f).filename().string(), "{\"trunc");

  write_file_atomic(target, "{}\n");
  EXPECT_EQ(read(target), "{}\n");
  EXPECT_FALSE(fs::exists(stale)) << "a dead writer's temporary file stays";
  EXPECT_TRUE(fs::exists(live)) << "a live writer's temporary file was removed";
  EXPECT_TRUE(fs::exists(other)) << "another target's temporary file was removed";
  EXPECT_TRUE(fs::exists(not_pid));
  EXPECT_FALSE(fs::exists(target + ".tmp." + std::to_string(::getpid())));
  EXPECT_EQ(remove_stale_temporaries(dir.file("other.json")), 1);
  EXPECT_FALSE(fs::exists(other));
  EXPECT_EQ(remove_stale_temporaries(dir.file("missing/x.json")),
            0);  // no folder: nothing, no throw
}

}  // namespace
}  // namespace mcf
