#pragma once
// Helpers for the harness tests: a fresh temporary folder per test, running the mcfbench binary.

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sys/wait.h>
#include <unistd.h>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace mcf::test {

namespace fs = std::filesystem;

inline fs::path fresh_dir(const std::string& name) {
  const fs::path d =
      fs::temp_directory_path() / ("mcfbench_bench_" + std::to_string(::getpid())) / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

inline std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

inline void write_text(const fs::path& p, const std::string& s) {
  std::ofstream(p) << s;
}

struct Command {
  int status = -1;
  std::string out, err;
};

/// Runs `mcfbench ARGS` in `cwd`, capturing stdout and stderr; `env` ("NAME=value ", shell-quoted)
/// is set for it.
inline Command mcfbench(const std::string& args, const fs::path& cwd, const std::string& env = "") {
  const fs::path out = cwd / ".stdout.txt", err = cwd / ".stderr.txt";
  const std::string cmd = "cd '" + cwd.string() + "' && " + env + MCFBENCH_BINARY + " " + args +
                          " >" + out.string() + " 2>" + err.string();
  const int raw = std::system(cmd.c_str());
  Command c;
  c.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  c.out = slurp(out);
  c.err = slurp(err);
  return c;
}

/// The cell result files (OUT/<hash>.json) of a folder.
inline std::vector<fs::path> result_files(const fs::path& dir) {
  std::vector<fs::path> v;
  if (!fs::is_directory(dir)) return v;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".json" && e.path().filename() != "index.json")
      v.push_back(e.path());
  std::sort(v.begin(), v.end());
  return v;
}

inline nlohmann::json read_json(const fs::path& p) {
  return nlohmann::json::parse(slurp(p));
}

}  // namespace mcf::test
