#include "harness/subprocess.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>

extern char** environ;

namespace mcf {
namespace {

/// The environment when the process started (static initialisation runs before main).
const std::vector<std::string>& startup_environment_copy() {
  static const std::vector<std::string> copy = [] {
    std::vector<std::string> entries;
    for (char** e = environ; e && *e; ++e) entries.emplace_back(*e);
    return entries;
  }();
  return copy;
}
[[maybe_unused]] const bool kTakenAtStart = !startup_environment_copy().empty();

}  // namespace

ProgramResult run_program(const std::vector<std::string>& argv, bool startup_environment) {
  if (argv.empty()) throw std::invalid_argument("run_program: no program");
  ProgramResult result;
  // What this process printed so far comes before the program's own lines.
  std::fflush(nullptr);
  int pipe_fds[2];
  if (::pipe2(pipe_fds, O_CLOEXEC) != 0) {
    result.start_error = std::string("cannot create a pipe: ") + std::strerror(errno);
    return result;
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], STDOUT_FILENO);
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  std::vector<char*> env;
  if (startup_environment) {
    for (const std::string& e : startup_environment_copy())
      env.push_back(const_cast<char*>(e.c_str()));
    env.push_back(nullptr);
  }
  const int spawn_error = ::posix_spawnp(&pid, args[0], &actions, nullptr, args.data(),
                                         startup_environment ? env.data() : environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(pipe_fds[1]);
  if (spawn_error != 0) {
    ::close(pipe_fds[0]);
    result.start_error = std::strerror(spawn_error);
    return result;
  }
  char buffer[4096];
  for (;;) {
    const ssize_t n = ::read(pipe_fds[0], buffer, sizeof buffer);
    if (n > 0) {
      result.out.append(buffer, size_t(n));
    } else if (n == 0 || errno != EINTR) {
      break;
    }
  }
  ::close(pipe_fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) {
      result.start_error = std::string("cannot wait for it: ") + std::strerror(errno);
      return result;
    }
  }
  result.status = WIFEXITED(status)     ? WEXITSTATUS(status)
                  : WIFSIGNALED(status) ? 128 + WTERMSIG(status)
                                        : -1;
  return result;
}

}  // namespace mcf
