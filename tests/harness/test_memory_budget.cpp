// The memory budget: sizes as users write them, MemAvailable as the kernel writes it, and the check
// that refuses an estimate over the budget with a message naming the flow, the estimate and the
// budget.

#include "harness/memory_budget.h"

#include <gtest/gtest.h>

#include <cmath>

namespace mcf {
namespace {

TEST(MemoryBudget, SizesAreBytesWithBinaryUnits) {
  EXPECT_EQ(parse_memory_size("8G", "--max-memory"), 8.0 * (1ull << 30));
  EXPECT_EQ(parse_memory_size("8GiB", "--max-memory"), 8.0 * (1ull << 30));
  EXPECT_EQ(parse_memory_size("1.5g", "--max-memory"), 1.5 * (1ull << 30));
  EXPECT_EQ(parse_memory_size("512M", "--max-memory"), 512.0 * (1ull << 20));
  EXPECT_EQ(parse_memory_size("300k", "--max-memory"), 300.0 * 1024);
  EXPECT_EQ(parse_memory_size("2T", "--max-memory"), 2.0 * (1ull << 40));
  EXPECT_EQ(parse_memory_size("123456789", "--max-memory"), 123456789.0);
  for (const char* bad : {"", "G", "8X", "-1G", "0", " 8G", "8 G", "nan", "inf", "1e999"}) try {
      parse_memory_size(bad, "--max-memory");
      ADD_FAILURE() << "accepted \"" << bad << "\"";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("--max-memory"), std::string::npos) << e.what();
    }
}

TEST(MemoryBudget, MemAvailableIsReadInKibibytes) {
  EXPECT_EQ(mem_available_from_meminfo("MemTotal:       24000000 kB\nMemFree:  100 kB\n"
                                       "MemAvailable:   20000000 kB\nBuffers: 5 kB\n"),
            20000000.0 * 1024);
  EXPECT_EQ(mem_available_from_meminfo("MemTotal: 24000000 kB\n"), -1);
  EXPECT_EQ(mem_available_from_meminfo("MemAvailable: lots\n"), -1);
}

TEST(MemoryBudget, ThisMachineHasSomeMemoryAndAResidentSet) {
  std::string source;
  const double available = available_memory_bytes(&source);
  EXPECT_GT(available, 0) << source;
  EXPECT_FALSE(source.empty());
  EXPECT_GT(resident_memory_bytes(), 1 << 20);  // a test process holds more than a megabyte
}

TEST(MemoryBudget, NoneTurnsTheCheckOffAndASizeBoundsTheTotal) {
  FlowConfig c;
  c.mesh = "sphere:vertices=90000000";
  MemoryEstimate huge;
  huge.mesh_bytes = 1e15;
  huge.dimension = 9e7;
  EXPECT_NO_THROW(check_memory(huge, memory_budget("none"), c, c.mesh));

  const MemoryBudget budget = memory_budget("16G");
  EXPECT_TRUE(budget.total);
  EXPECT_EQ(budget.bytes, 16.0 * (1ull << 30));
  MemoryEstimate small;
  small.resident_bytes = 15.0 * (1ull << 30);
  small.mesh_bytes = 0.5 * (1ull << 30);
  EXPECT_NO_THROW(check_memory(small, budget, c, c.mesh));
  small.mesh_bytes = 1.5 * (1ull << 30);  // the resident part counts against a --max-memory
  EXPECT_THROW(check_memory(small, budget, c, c.mesh), MemoryLimitError);
  try {
    check_memory(huge, budget, c, c.mesh);
    ADD_FAILURE() << "not refused";
  } catch (const MemoryLimitError& e) {
    const std::string m = e.what();
    for (const char* part :
         {"sphere:vertices=90000000", "estimated", "931322.57 GiB", "16.00 GiB", "--max-memory"})
      EXPECT_NE(m.find(part), std::string::npos) << part << " in: " << m;
  }
}

TEST(MemoryBudget, TheAvailableMemoryBoundsWhatTheFlowAdds) {
  FlowConfig c;
  MemoryBudget available;
  available.bytes = 1e9;
  available.source = "MemAvailable of /proc/meminfo";
  MemoryEstimate e;
  e.resident_bytes = 5e9;  // already held: not part of what must still be found
  e.mesh_bytes = 0.9e9;
  EXPECT_NO_THROW(check_memory(e, available, c, "x"));
  e.mesh_bytes = 1.1e9;
  EXPECT_THROW(check_memory(e, available, c, "x"), MemoryLimitError);
}

}  // namespace
}  // namespace mcf
