#include "harness/result_record.h"

#include "harness/environment.h"
#include "harness/timing_summary.h"

#include <fstream>
#include <string>

namespace mcf {
namespace {

/// Resets the process's peak-memory mark: Linux resets the high-water mark (VmHWM) when "5" is
/// written to /proc/self/clear_refs. False where that fails; the process's peak (getrusage) is
/// then recorded, and said so.
bool reset_peak_memory() {
  std::ofstream f("/proc/self/clear_refs");
  if (!f) return false;
  f << "5";
  f.flush();
  return bool(f);
}

/// The peak since the last reset (VmHWM of /proc/self/status), else the process's peak.
long long peak_memory_since_reset_bytes() {
  std::ifstream f("/proc/self/status");
  std::string line;
  while (std::getline(f, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::stoll(line.substr(6)) * 1024;  // kB
  return peak_memory_bytes();
}

}  // namespace

ResultRecorder::ResultRecorder(bool peak_of_this_flow)
    : start_(std::chrono::steady_clock::now()),
      peak_reset_(peak_of_this_flow && reset_peak_memory()),
      steal_before_(cpu_steal_seconds()),
      counters_before_(read_cpu_counters()) {}

void ResultRecorder::complete(nlohmann::json& result, int threads,
                              const nlohmann::json& memory_estimate,
                              const MemoryBudget& budget) const {
  result["environment"] = environment_json(threads, result);
  result["peak_memory_bytes"] = peak_reset_ ? peak_memory_since_reset_bytes() : peak_memory_bytes();
  result["peak_memory_scope"] = peak_reset_ ? "cell" : "process";
  if (!memory_estimate.is_null()) result["memory_estimate"] = memory_estimate;
  result["memory_budget"] = budget.to_json();
  result["run_seconds"] =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  if (const double steal = cpu_steal_seconds_since(steal_before_); steal >= 0)
    result["steal_seconds"] = steal;
  result["contention"] = contention_json(counters_before_, read_cpu_counters(),
                                         result["environment"].value("cores", 0));
  if (nlohmann::json t = timing_summary(result); !t.empty()) result["timing"] = std::move(t);
}

}  // namespace mcf
