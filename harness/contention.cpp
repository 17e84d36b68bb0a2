#include "harness/contention.h"

#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace mcf {

bool parse_proc_stat_cpu(const std::string& text, long ticks_per_second, double& busy,
                         double& steal) {
  std::istringstream in(text);
  std::string label;
  in >> label;
  if (label != "cpu" || ticks_per_second <= 0) return false;
  // user nice system idle iowait irq softirq steal (proc(5)); guest time is inside user.
  unsigned long long v[8];
  for (auto& x : v)
    if (!(in >> x)) return false;
  const double hz = double(ticks_per_second);
  busy = double(v[0] + v[1] + v[2] + v[5] + v[6]) / hz;
  steal = double(v[7]) / hz;
  return true;
}

CpuCounters read_cpu_counters() {
  CpuCounters c;
  c.wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  {
    std::ifstream in("/proc/stat");
    std::string line;
    if (std::getline(in, line)) {
      double busy = 0, steal = 0;
      const long hz = ::sysconf(_SC_CLK_TCK);
      if (parse_proc_stat_cpu(line, hz, busy, steal)) {
        c.busy = busy;
        c.steal = steal;
        c.tick = 1.0 / double(hz);
      }
    }
  }
  // This process's time and that of its children it has waited for (and theirs): a cell run
  // under mpirun (mpi_ranks) is its own work, not other work beside it.
  rusage self{}, children{};
  if (::getrusage(RUSAGE_SELF, &self) == 0 && ::getrusage(RUSAGE_CHILDREN, &children) == 0)
    c.own = double(self.ru_utime.tv_sec + self.ru_stime.tv_sec + children.ru_utime.tv_sec +
                   children.ru_stime.tv_sec) +
            1e-6 * double(self.ru_utime.tv_usec + self.ru_stime.tv_usec +
                          children.ru_utime.tv_usec + children.ru_stime.tv_usec);
  std::ifstream load("/proc/loadavg");
  if (double l = 0; load >> l) c.load1 = l;
  return c;
}

nlohmann::json contention_json(const CpuCounters& before, const CpuCounters& after, int cores) {
  nlohmann::json j;
  const double wall = after.wall - before.wall;
  j["seconds"] = wall;
  j["cores"] = cores;
  if (before.load1 >= 0 && after.load1 >= 0) j["load_average"] = {before.load1, after.load1};
  bool contended = false;
  std::string reason;
  // The counters of all CPUs each round to a tick: less than that is no evidence.
  const double resolution = std::max(before.tick, after.tick) * std::max(cores, 1);
  if (wall > 0 && before.busy >= 0 && after.busy >= 0 && before.own >= 0 && after.own >= 0) {
    // The kernel's busy time and this process's CPU time tick at different granularities: the
    // difference is clamped at zero.
    const double other = std::max(0.0, (after.busy - before.busy) - (after.own - before.own));
    j["other_cores"] = other / wall;
    if (other > kContendedOtherCores * wall + resolution) {
      contended = true;
      char text[96];
      std::snprintf(text, sizeof text, "other processes used %.2f cores", other / wall);
      reason = text;
    }
  }
  if (wall > 0 && before.steal >= 0 && after.steal >= 0) {
    const double stolen = after.steal - before.steal;
    const double steal = stolen / wall;
    j["steal_cores"] = steal;
    if (stolen > kContendedStealCores * wall + resolution) {
      char text[96];
      std::snprintf(text, sizeof text, "the hypervisor took %.2f cores", steal);
      reason += (reason.empty() ? "" : "; ") + std::string(text);
      contended = true;
    }
  }
  j["contended"] = contended;
  if (contended) j["reason"] = reason;
  return j;
}

}  // namespace mcf
