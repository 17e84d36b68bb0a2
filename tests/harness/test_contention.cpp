// Contention from fabricated counters, /proc/stat parsing, and the timing summary of a result.
#include "harness/contention.h"
#include "harness/subprocess.h"
#include "harness/timing_summary.h"

#include <gtest/gtest.h>

#include <sys/resource.h>

namespace mcf {
namespace {

using nlohmann::json;

CpuCounters at(double wall, double busy, double own, double steal) {
  CpuCounters c;
  c.wall = wall;
  c.busy = busy;
  c.own = own;
  c.steal = steal;
  c.load1 = 1.0;
  return c;
}

TEST(Contention, OtherProcessesTimeMarksACell) {
  // 10 s: the machine was busy 20 CPU-seconds, 19.5 of them this process's: quiet.
  json quiet = contention_json(at(0, 100, 10, 5), at(10, 120, 29.5, 5.1), 2);
  EXPECT_FALSE(quiet["contended"].get<bool>());
  EXPECT_NEAR(quiet["other_cores"].get<double>(), 0.05, 1e-12);
  EXPECT_NEAR(quiet["steal_cores"].get<double>(), 0.01, 1e-12);
  EXPECT_FALSE(quiet.contains("reason"));
  // A build beside it: 9 CPU-seconds of others in 10 s.
  json busy = contention_json(at(0, 100, 10, 5), at(10, 129, 30, 5), 2);
  EXPECT_TRUE(busy["contended"].get<bool>());
  EXPECT_NE(busy["reason"].get<std::string>().find("0.90 cores"), std::string::npos);
  // The hypervisor took a tenth of a core.
  EXPECT_TRUE(contention_json(at(0, 0, 0, 0), at(10, 10, 10, 1), 2)["contended"].get<bool>());
  // A short cell: one 10 ms tick of steal or of other work on each of 2 CPUs in 0.17 s is the
  // counters' rounding, not evidence (0.06 and 0.12 cores read); five ticks are.
  CpuCounters b = at(0, 100, 10, 5), e = at(0.17, 100.34, 10.32, 5.01);
  b.tick = e.tick = 0.01;
  EXPECT_FALSE(contention_json(b, e, 2)["contended"].get<bool>()) << contention_json(b, e, 2);
  e.steal = 5.05;
  EXPECT_TRUE(contention_json(b, e, 2)["contended"].get<bool>());
  e.steal = 5.01;
  e.busy = 100.40;  // 0.08 s of others: 0.47 cores
  EXPECT_TRUE(contention_json(b, e, 2)["contended"].get<bool>());
  // Unknown counters never mark a cell.
  EXPECT_FALSE(contention_json(at(0, -1, -1, -1), at(10, -1, -1, -1), 2)["contended"].get<bool>());
}

// A child the process waits for (a cell's mpirun) is counted as the process's own time, so its
// work is not taken for other work sharing the cores.
TEST(Contention, WaitedForChildrenCountAsOwnTime) {
  const auto children_seconds = [] {
    rusage u{};
    if (::getrusage(RUSAGE_CHILDREN, &u) != 0) return -1.0;
    return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
           1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
  };
  const CpuCounters before = read_cpu_counters();
  const double children_before = children_seconds();
  if (before.own < 0 || children_before < 0) GTEST_SKIP() << "no getrusage";
  const ProgramResult r =
      run_program({"awk", "BEGIN { for (i = 0; i < 20000000; ++i) s += i; print s }"});
  ASSERT_TRUE(r.ok()) << r.start_error;
  const CpuCounters after = read_cpu_counters();
  const double child = children_seconds() - children_before;  // the kernel's count of the child
  ASSERT_GT(child, 0.05) << "the child did too little work to measure";
  EXPECT_GE(after.own - before.own, child) << "the child's CPU time is not in `own`";
}

TEST(Contention, ProcStatLine) {
  double busy = 0, steal = 0;
  ASSERT_TRUE(parse_proc_stat_cpu("cpu  100 10 50 1000 7 3 2 40 0 0", 100, busy, steal));
  EXPECT_DOUBLE_EQ(busy, 1.65);  // user + nice + system + irq + softirq
  EXPECT_DOUBLE_EQ(steal, 0.4);
  EXPECT_FALSE(parse_proc_stat_cpu("cpu0 1 2 3 4 5 6 7 8", 100, busy, steal));
  EXPECT_FALSE(parse_proc_stat_cpu("cpu 1 2 3", 100, busy, steal));
  const CpuCounters now = read_cpu_counters();
  EXPECT_GE(now.own, 0.0);
}

TEST(TimingSummary, MedianOfTheStepsAfterTheFirst) {
  json r = {{"system", {{"setup_seconds", {{"total", 2.0}}}}},
            {"steps",
             {{{"seconds", {{"total", 9.0}}}},
              {{"seconds", {{"total", 1.0}}}},
              {{"seconds", {{"total", 3.0}}}},
              {{"seconds", {{"total", 2.0}}}},
              {{"seconds", {{"total", 100.0}}}}}}};
  const json t = timing_summary(r);
  EXPECT_DOUBLE_EQ(t["step_median_seconds"].get<double>(), 2.5);  // of 1, 3, 2, 100
  EXPECT_EQ(t["steps_timed"], 4);
  EXPECT_DOUBLE_EQ(t["first_step_seconds"].get<double>(), 9.0);
  EXPECT_DOUBLE_EQ(t["flow_seconds"].get<double>(), 117.0);
  r["steps"] = json::array({{{"seconds", {{"total", 4.0}}}}});
  EXPECT_DOUBLE_EQ(timing_summary(r)["step_median_seconds"].get<double>(), 4.0);
  EXPECT_TRUE(timing_summary(json{{"steps", json::array()}}).empty());
}

}  // namespace
}  // namespace mcf
