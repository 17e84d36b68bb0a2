#include "harness/history_tool.h"

#include "harness/environment.h"

#include <unistd.h>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>

namespace mcf {

std::string history_script() {
  if (const char* s = std::getenv("MCFBENCH_HISTORY_SCRIPT"); s && *s) return s;
  return source_dir() + "/reports/perf_history.py";
}

int run_history_tool(const std::vector<std::string>& args) {
  const std::string script = history_script();
  if (!std::filesystem::is_regular_file(script))
    throw std::runtime_error(script +
                             ": the history script is missing (the binary runs the one of the "
                             "source tree it was built from; MCFBENCH_HISTORY_SCRIPT names "
                             "another)");
  // matplotlib and numpy are Debian's, for this interpreter only.
  const char* python = "/usr/bin/python3";
  std::vector<char*> argv;
  argv.push_back(const_cast<char*>(python));
  argv.push_back(const_cast<char*>(script.c_str()));
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  std::fflush(stdout);
  std::fflush(stderr);
  ::execv(python, argv.data());
  throw std::runtime_error(std::string(python) + ": cannot run it: " + std::strerror(errno));
}

}  // namespace mcf
