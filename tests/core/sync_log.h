#pragma once
// Watches fsync: a crash of the machine cannot be staged in a test, so the durable-write tests
// check the calls instead. This header interposes fsync for the test executable that includes
// it (a definition there takes precedence over the C library's for every object linked into it)
// and records which path each call flushed. Include it from one source file per executable.

#include <gtest/gtest.h>

#include <sys/syscall.h>
#include <unistd.h>
#include <climits>
#include <filesystem>
#include <string>
#include <vector>

namespace mcf::test {

struct SyncLog {
  bool on = false;
  std::vector<std::string> paths;  // what each fsync flushed, in call order
};
inline SyncLog sync_log;

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
inline void expect_file_then_folder(const std::vector<std::string>& syncs,
                                    const std::filesystem::path& target,
                                    const std::string& temporary_marker) {
  namespace fs = std::filesystem;
  ASSERT_EQ(syncs.size(), 2u) << "expected the temporary file, then the folder, to be synced";
  const fs::path file(syncs[0]);
  EXPECT_EQ(fs::canonical(file.parent_path()), fs::canonical(target.parent_path()));
  EXPECT_NE(file.filename().string().find(temporary_marker), std::string::npos)
      << syncs[0] << ": the temporary file is synced before it is renamed";
  EXPECT_EQ(fs::canonical(syncs[1]), fs::canonical(target.parent_path())) << "then the folder";
}

}  // namespace mcf::test

extern "C" int fsync(int fd) {
  if (mcf::test::sync_log.on) {
    char buf[PATH_MAX];
    const std::string link = "/proc/self/fd/" + std::to_string(fd);
    const ssize_t n = ::readlink(link.c_str(), buf, sizeof buf);
    mcf::test::sync_log.paths.push_back(n > 0 ? std::string(buf, std::size_t(n)) : "?");
  }
  return int(::syscall(SYS_fsync, fd));
}
