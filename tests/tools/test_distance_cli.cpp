// `mcfbench distance` end to end: files are read as is (no unit-cube rescaling), the JSON has
// every key, and a missing file fails naming it.

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

namespace {

namespace fs = std::filesystem;

/// stdout of a command and its exit status.
std::pair<int, std::string> capture(const std::string& cmd) {
  std::string out;
  FILE* pipe = popen((cmd + " 2>&1").c_str(), "r");
  if (!pipe) return {-1, out};
  char buf[4096];
  while (std::size_t n = std::fread(buf, 1, sizeof buf, pipe)) out.append(buf, n);
  const int raw = pclose(pipe);
  return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, out};
}

/// Two triangles covering [0,s]² at height z, as an OFF file.
fs::path square(const fs::path& dir, const std::string& name, double s, double z) {
  const fs::path p = dir / name;
  std::ofstream f(p);
  f << "OFF\n4 2 0\n0 0 " << z << "\n"
    << s << " 0 " << z << "\n"
    << s << " " << s << " " << z << "\n0 " << s << " " << z << "\n3 0 1 2\n3 0 2 3\n";
  return p;
}

TEST(DistanceCli, FilesAreComparedUnscaled) {
  const fs::path dir =
      fs::temp_directory_path() / ("mcfbench_distance_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  // A 3×3 square and a copy 0.25 above it: unit-cube scaling would make the gap 1/12.
  const fs::path a = square(dir, "a.off", 3.0, 0.0), b = square(dir, "b.off", 3.0, 0.25);
  const auto [status, out] = capture(std::string(MCFBENCH_BINARY) + " distance " + a.string() +
                                     " " + b.string() + " --samples 2000 --seed 3");
  ASSERT_EQ(status, 0) << out;
  const nlohmann::json j = nlohmann::json::parse(out);
  for (const char* key :
       {"rms_forward", "max_forward", "rms_backward", "max_backward", "rms", "max"})
    EXPECT_NEAR(j.at(key).get<double>(), 0.25, 1e-6) << key;  // OFF stores 17 digits
  EXPECT_EQ(j.at("samples").get<long long>(), 2000);

  const auto [bad, msg] = capture(std::string(MCFBENCH_BINARY) + " distance " +
                                  (dir / "missing.off").string() + " " + b.string());
  EXPECT_NE(bad, 0);
  EXPECT_NE(msg.find("missing.off"), std::string::npos) << msg;
  fs::remove_all(dir);
}

TEST(DistanceCli, MeshSpecsWork) {
  const auto [status, out] =
      capture(std::string(MCFBENCH_BINARY) +
              " distance icosphere:level=3 icosphere:level=3 --samples 1000");
  ASSERT_EQ(status, 0) << out;
  EXPECT_LT(nlohmann::json::parse(out).at("max").get<double>(), 1e-12);
}

}  // namespace
