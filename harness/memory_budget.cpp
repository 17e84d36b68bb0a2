#include "harness/memory_budget.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace mcf {
namespace {

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  if (!in) return {};
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A control group's limit or usage in bytes; -1 for "max", a missing file or a limit so large
/// that it means none (v1 writes 2^63 rounded to a page).
double cgroup_value(const std::string& path) {
  const std::string text = read_text(path);
  if (text.empty() || text.rfind("max", 0) == 0) return -1;
  const double v = std::strtod(text.c_str(), nullptr);
  return v > 0 && v < std::ldexp(1.0, 60) ? v : -1;
}

/// The room left in this process's memory control group: limit minus usage, -1 without a limit.
/// A cgroup namespace mounts the process's own group at the root; otherwise /proc/self/cgroup
/// names its path under the hierarchy.
double cgroup_room(std::string& source) {
  std::string v2_path, v1_path;
  std::istringstream lines(read_text("/proc/self/cgroup"));
  for (std::string line; std::getline(lines, line);) {
    const auto a = line.find(':'), b = line.find(':', a + 1);
    if (a == std::string::npos || b == std::string::npos) continue;
    const std::string controllers = line.substr(a + 1, b - a - 1), path = line.substr(b + 1);
    if (line.rfind("0::", 0) == 0) v2_path = path;
    if (("," + controllers + ",").find(",memory,") != std::string::npos) v1_path = path;
  }
  const std::pair<std::string, std::string> groups[] = {
      {"/sys/fs/cgroup" + v2_path + "/memory.max", "/sys/fs/cgroup" + v2_path + "/memory.current"},
      {"/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory.current"},
      {"/sys/fs/cgroup/memory" + v1_path + "/memory.limit_in_bytes",
       "/sys/fs/cgroup/memory" + v1_path + "/memory.usage_in_bytes"},
      {"/sys/fs/cgroup/memory/memory.limit_in_bytes",
       "/sys/fs/cgroup/memory/memory.usage_in_bytes"}};
  double room = -1;
  for (const auto& [limit_file, usage_file] : groups) {
    const double limit = cgroup_value(limit_file), usage = cgroup_value(usage_file);
    if (limit < 0) continue;
    const double left = std::max(0.0, limit - std::max(0.0, usage));
    if (room < 0 || left < room) {
      room = left;
      source = "the memory control group's limit (" + limit_file + ")";
    }
  }
  return room;
}

}  // namespace

nlohmann::json MemoryBudget::to_json() const {
  nlohmann::json j = {{"source", source}, {"total", total}};
  if (bytes >= 0) j["bytes"] = bytes;
  return j;
}

double parse_memory_size(const std::string& text, const std::string& what) {
  const char* begin = text.c_str();
  char* end = nullptr;
  const double value = std::strtod(begin, &end);
  std::string unit(end);
  std::transform(unit.begin(), unit.end(), unit.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  double scale = -1;
  if (unit.empty() || unit == "b")
    scale = 1;
  else if (unit == "k" || unit == "kb" || unit == "kib")
    scale = std::ldexp(1.0, 10);
  else if (unit == "m" || unit == "mb" || unit == "mib")
    scale = std::ldexp(1.0, 20);
  else if (unit == "g" || unit == "gb" || unit == "gib")
    scale = std::ldexp(1.0, 30);
  else if (unit == "t" || unit == "tb" || unit == "tib")
    scale = std::ldexp(1.0, 40);
  if (end == begin || scale < 0 || !std::isfinite(value) || value <= 0 ||
      std::isspace(static_cast<unsigned char>(text.front())))
    throw std::invalid_argument(what + ": expected a size such as 8G, 512M or none, got \"" + text +
                                "\"");
  return value * scale;
}

MemoryBudget memory_budget(const std::string& max_memory) {
  MemoryBudget b;
  if (max_memory == "none") {
    b.source = "--max-memory none";
  } else if (!max_memory.empty()) {
    b.bytes = parse_memory_size(max_memory, "--max-memory");
    b.total = true;
    b.source = "--max-memory " + max_memory;
  } else {
    b.bytes = available_memory_bytes(&b.source);
    if (b.bytes < 0) b.source = "unknown (neither /proc/meminfo nor a control group could be read)";
  }
  return b;
}

double mem_available_from_meminfo(const std::string& text) {
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);)
    if (line.rfind("MemAvailable:", 0) == 0) {
      std::istringstream fields(line.substr(13));
      double kib = -1;
      std::string unit;
      if (fields >> kib >> unit && unit == "kB" && kib >= 0) return kib * 1024;
      return -1;
    }
  return -1;
}

double available_memory_bytes(std::string* source) {
  std::string why = "MemAvailable of /proc/meminfo";
  double available = mem_available_from_meminfo(read_text("/proc/meminfo"));
  std::string group_source;
  const double room = cgroup_room(group_source);
  if (room >= 0 && (available < 0 || room < available)) {
    available = room;
    why = group_source;
  }
  if (source) *source = why;
  return available;
}

double resident_memory_bytes() {
  std::istringstream lines(read_text("/proc/self/status"));
  for (std::string line; std::getline(lines, line);)
    if (line.rfind("VmRSS:", 0) == 0) return std::strtod(line.c_str() + 6, nullptr) * 1024;
  return 0;
}

void check_memory(const MemoryEstimate& estimate, const MemoryBudget& budget,
                  const FlowConfig& config, const std::string& what) {
  if (budget.bytes < 0) return;
  const double needed =
      budget.total ? estimate.total() : estimate.total() - estimate.resident_bytes;
  if (needed <= budget.bytes) return;
  std::string message =
      what + ": the flow needs an estimated " + estimate.describe(config) + ", more than ";
  if (budget.total)
    message += budget.source + " allows (" + format_gib(budget.bytes) + ")";
  else
    message += "the " + format_gib(budget.bytes) + " available (" + budget.source + "; " +
               format_gib(estimate.resident_bytes) + " already held by this process)";
  message +=
      "; use a smaller mesh or depth, or --max-memory SIZE (none: no check) if the estimate is "
      "wrong for this machine";
  throw MemoryLimitError(message);
}

MemoryEstimate checked_memory_estimate(const FlowConfig& config, const FlowSizes& sizes,
                                       const MemoryBudget& budget, const std::string& what) {
  const MemoryEstimate e = estimate_flow_memory(config, sizes, resident_memory_bytes());
  check_memory(e, budget, config, what);
  return e;
}

}  // namespace mcf
