// write_file_atomic: a temporary file a killed writer of this machine left beside its target
// (TARGET.tmp.HOST.PID, or the older TARGET.tmp.PID, of a process that is gone) is removed by the
// next write of that target; those of live processes, of other targets and of other machines
// (a writer on another node of a shared file system, whose processes this one cannot see) stay.

#include "core/atomic_file.h"
#include "temp_dir.h"

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

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
  const std::string host = temporary_host_name();
  const std::string stale = target + ".tmp." + host + "." + std::to_string(dead);
  const std::string stale_unnamed = target + ".tmp." + std::to_string(dead);
  const std::string live =
      target + ".tmp." + host + "." + std::to_string(::getppid());  // our parent is alive
  const std::string other = dir.file("other.json.tmp." + host + "." + std::to_string(dead));
  const std::string elsewhere = target + ".tmp.node-17." + std::to_string(dead);
  const std::string not_pid = target + ".tmp.notes";
  for (const std::string& f : {stale, stale_unnamed, live, other, elsewhere, not_pid})
    dir.write(fs::path(f).filename().string(), "{\"trunc");

  write_file_atomic(target, "{}\n");
  EXPECT_EQ(read(target), "{}\n");
  EXPECT_FALSE(fs::exists(stale)) << "a dead writer's temporary file stays";
  EXPECT_FALSE(fs::exists(stale_unnamed)) << "a dead writer's temporary file (PID only) stays";
  EXPECT_TRUE(fs::exists(live)) << "a live writer's temporary file was removed";
  EXPECT_TRUE(fs::exists(other)) << "another target's temporary file was removed";
  EXPECT_TRUE(fs::exists(elsewhere)) << "another machine's temporary file was removed";
  EXPECT_TRUE(fs::exists(not_pid));
  EXPECT_FALSE(fs::exists(target + ".tmp." + host + "." + std::to_string(::getpid())));
  EXPECT_EQ(remove_stale_temporaries(dir.file("other.json")), 1);
  EXPECT_FALSE(fs::exists(other));
  EXPECT_EQ(remove_stale_temporaries(dir.file("missing/x.json")),
            0);  // no folder: nothing, no throw
}

TEST(AtomicFile, TheTemporaryFileNamesItsMachineAndProcess) {
  const std::string host = temporary_host_name();
  ASSERT_FALSE(host.empty());
  EXPECT_EQ(
      host.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-_"),
      std::string::npos)
      << host;
  // A folder where the temporary file would go makes the write fail naming that file.
  test::TempDir dir;
  const std::string target = dir.file("plan.json");
  const std::string tmp = target + ".tmp." + host + "." + std::to_string(::getpid());
  fs::create_directories(tmp);
  try {
    write_file_atomic(target, "{}\n");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(tmp), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(target));
}

}  // namespace
}  // namespace mcf
