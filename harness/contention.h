#pragma once
// Whether a measurement shared the machine: the CPU time other processes and the hypervisor took
// while a cell ran, from /proc/stat and this process's own CPU time. A timing taken while other
// work ran is not a measurement of the method (CHOLMOD's spinning BLAS threads run several times
// slower when oversubscribed), so a cell records what it saw and the reports set such cells apart.

#include <nlohmann/json.hpp>

#include <string>

namespace mcf {

/// One reading of the counters (seconds, summed over all CPUs; negative where unknown).
struct CpuCounters {
  double busy = -1;   ///< user + nice + system + irq + softirq of the whole machine
  double steal = -1;  ///< time the hypervisor gave to other guests
  double own =
      -1;  ///< user + system time of this process (all its threads) and its waited-for children
  double wall = 0;    ///< a monotonic clock
  double load1 = -1;  ///< /proc/loadavg's one-minute load average
  /// The resolution of busy and steal: one tick of /proc/stat's clock per CPU (1/CLK_TCK s); 0
  /// for exact counters.
  double tick = 0;
};

/// The fields of /proc/stat's aggregate `cpu` line `text` at `ticks_per_second`: busy and steal
/// in seconds; false if the line is not such a line.
bool parse_proc_stat_cpu(const std::string& text, long ticks_per_second, double& busy,
                         double& steal);

CpuCounters read_cpu_counters();

/// A contended measurement: other processes used more than this many cores on average, or the
/// hypervisor took more than this fraction of one core. A quiet guest's daemons use about 0.01.
/// Either must also exceed what the counters can resolve, one tick per CPU: in a cell of 0.17 s a
/// single 10 ms tick of steal reads as 0.06 cores, a rounding of the counter, not a measurement.
inline constexpr double kContendedOtherCores = 0.2;
inline constexpr double kContendedStealCores = 0.05;

/// What happened between two readings: {"seconds", "other_cores" (CPU time of other processes
/// over the wall time, in cores), "steal_cores", "load_average" [start, end], "cores",
/// "contended" (bool), "reason" (when contended)}. Unknown counters are left out and never make
/// a cell contended.
nlohmann::json contention_json(const CpuCounters& before, const CpuCounters& after, int cores);

}  // namespace mcf
