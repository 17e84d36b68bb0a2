#include "harness/environment.h"

#include "build_info.h"
#include "core/parallel.h"
#include "flows/planted_slowdown.h"

#include <OpenMesh/Core/System/config.h>
#include <suitesparse/cholmod.h>
#include <tbb/version.h>
#include <Eigen/Core>

#include <sys/resource.h>
#include <unistd.h>
#include <algorithm>
#include <exception>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

namespace mcf {
namespace {

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) {
      const auto colon = line.find(':');
      if (colon != std::string::npos) return line.substr(line.find_first_not_of(' ', colon + 1));
    }
  return "unknown";
}

std::string hostname() {
  char buf[256] = {};
  return ::gethostname(buf, sizeof buf - 1) == 0 ? buf : "unknown";
}

}  // namespace

nlohmann::json environment_json(int threads, const nlohmann::json& result) {
  // CHOLMOD records the OpenBLAS threads it ran with (solver_settings, solvers/cholmod_solver.h);
  // under any other solver OpenBLAS stays at the flow's cap, `threads`.
  int blas_threads = 0;
  if (result.is_object() && result.contains("solver_settings")) {
    const nlohmann::json& settings = result["solver_settings"];
    if (settings.is_object() && settings.contains("blas_threads") &&
        settings["blas_threads"].is_string()) {
      try {
        blas_threads = std::stoi(settings["blas_threads"].get<std::string>());
      } catch (const std::exception&) {
        blas_threads = 0;
      }
    }
  }
  return environment_json(threads, blas_threads);
}

nlohmann::json environment_json(int threads, int blas_threads) {
  const int cores = int(std::thread::hardware_concurrency());
  // What ran in parallel: TBB's arena never exceeds default_concurrency(), whatever the config
  // asked for (that request is in "config.threads"); OpenBLAS, under CHOLMOD, ran with the count
  // the solver chose (solvers/cholmod_solver.h), else at the same cap.
  const int ran = runnable_threads(threads);
  const auto v = [](int a, int b, int c) {
    return std::to_string(a) + "." + std::to_string(b) + "." + std::to_string(c);
  };
  nlohmann::json env = {
      {"commit", MCFBENCH_GIT_COMMIT},
      {"version", MCFBENCH_VERSION},
      {"cpu", cpu_model()},
      {"cores", cores},
      {"threads", ran},
      {"blas_threads", blas_threads > 0 ? blas_threads : ran},
      {"hostname", hostname()},
      {"build",
       {{"type", MCFBENCH_BUILD_TYPE},
        {"compiler", MCFBENCH_CXX_COMPILER},
        {"march_native", MCFBENCH_MARCH_NATIVE},
        {"sanitized", MCFBENCH_SANITIZED}}},
      {"libraries",
       {{"eigen", v(EIGEN_WORLD_VERSION, EIGEN_MAJOR_VERSION, EIGEN_MINOR_VERSION)},
        {"cholmod", v(CHOLMOD_MAIN_VERSION, CHOLMOD_SUB_VERSION, CHOLMOD_SUBSUB_VERSION)},
        {"suitesparse",
         v(SUITESPARSE_MAIN_VERSION, SUITESPARSE_SUB_VERSION, SUITESPARSE_SUBSUB_VERSION)},
        {"tbb", TBB_VERSION_STRING},
        {"openmesh", std::to_string((OM_VERSION >> 16) & 0xFF) + "." +
                         std::to_string((OM_VERSION >> 8) & 0xFF)},
        {"nlohmann_json",
         v(NLOHMANN_JSON_VERSION_MAJOR, NLOHMANN_JSON_VERSION_MINOR, NLOHMANN_JSON_VERSION_PATCH)},
        {"blas", "openblas"}}}};
  // A run slowed on purpose says so (flows/planted_slowdown.h); the key is absent otherwise.
  if (const double f = planted_slowdown(); f > 0) {
    env["planted_slowdown"] = f;
    env["planted_phase"] = to_string(planted_phase());
  }
  return env;
}

std::string source_dir() {
  return MCFBENCH_SOURCE_DIR;
}

long long peak_memory_bytes() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<long long>(u.ru_maxrss) * 1024;
}

double steal_seconds_from_proc_stat(const std::string& text, long ticks_per_second) {
  std::istringstream in(text);
  std::string label;
  in >> label;
  if (label != "cpu" || ticks_per_second <= 0) return -1;
  // user nice system idle iowait irq softirq steal (proc(5))
  unsigned long long value = 0;
  for (int field = 1; field <= 8; ++field)
    if (!(in >> value)) return -1;
  return double(value) / double(ticks_per_second);
}

double cpu_steal_seconds() {
  std::ifstream in("/proc/stat");
  std::string line;
  if (!std::getline(in, line)) return -1;
  return steal_seconds_from_proc_stat(line, ::sysconf(_SC_CLK_TCK));
}

double cpu_steal_seconds_since(double before) {
  const double now = cpu_steal_seconds();
  return before >= 0 && now >= 0 ? now - before : -1;
}

}  // namespace mcf
