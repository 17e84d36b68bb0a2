// harness/environment: the hypervisor's stolen time (the provenance block is checked through the
// binary, tests/tools/test_cli.cpp).

#include "harness/environment.h"

#include <gtest/gtest.h>

#include <fstream>

namespace mcf {
namespace {

TEST(Environment, TheBuildSaysHowItWasCompiled) {
  // Results of a -march=native build and of a portable one differ in their last bits (FMA,
  // vector widths): a result says which it came from.
  const nlohmann::json b = environment_json(1)["build"];
  ASSERT_TRUE(b.contains("march_native") && b["march_native"].is_boolean());
  ASSERT_TRUE(b.contains("sanitized") && b["sanitized"].is_boolean());
#if defined(__SANITIZE_ADDRESS__)
  EXPECT_TRUE(b["sanitized"].get<bool>());
#endif
  EXPECT_FALSE(b.value("type", "").empty());
}

TEST(Environment, StealIsTheEighthValueOfTheAggregateCpuLine) {
  // proc(5): cpu user nice system idle iowait irq softirq steal guest guest_nice
  EXPECT_DOUBLE_EQ(
      steal_seconds_from_proc_stat("cpu  7337056 73943 1480949 5784732 7154 0 1097 70074 0 0", 100),
      700.74);
  EXPECT_DOUBLE_EQ(steal_seconds_from_proc_stat("cpu 1 2 3 4 5 6 7 250", 250), 1.0);
  // Not the aggregate line, too few values, no tick rate: unknown.
  EXPECT_EQ(steal_seconds_from_proc_stat("cpu0 1 2 3 4 5 6 7 8", 100), -1);
  EXPECT_EQ(steal_seconds_from_proc_stat("cpu 1 2 3 4 5 6 7", 100), -1);
  EXPECT_EQ(steal_seconds_from_proc_stat("", 100), -1);
  EXPECT_EQ(steal_seconds_from_proc_stat("cpu 1 2 3 4 5 6 7 8", 0), -1);
}

TEST(Environment, StealSecondsNeverGoBackwards) {
  const double a = cpu_steal_seconds();
  if (!std::ifstream("/proc/stat")) {
    EXPECT_EQ(a, -1);
    return;
  }
  ASSERT_GE(a, 0);  // every Linux since 2.6.11 reports it
  EXPECT_GE(cpu_steal_seconds(), a);
}

}  // namespace
}  // namespace mcf
