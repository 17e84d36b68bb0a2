// `mcfbench history`: the arguments reach the history tool (reports/perf_history.py, tested on
// its own by ctest `history`), its exit status is the command's, and a missing script is named.

#include "harness/history_tool.h"

#include "harness_test_util.h"

namespace mcf {
namespace {

using namespace mcf::test;

TEST(HistoryTool, ArgumentsAndExitStatusPassThrough) {
  const fs::path dir = fresh_dir("history_tool");
  Command c = mcfbench("history detect --store empty", dir);
  EXPECT_EQ(c.status, 0) << c.out << c.err;
  EXPECT_NE(c.out.find("no step change in empty"), std::string::npos) << c.out;
  c = mcfbench("history publish site --store empty", dir);
  EXPECT_EQ(c.status, 0) << c.out << c.err;
  EXPECT_TRUE(fs::exists(dir / "site" / "index.html"));
  c = mcfbench("history bisect", dir);  // the tool's own usage error
  EXPECT_EQ(c.status, 2) << c.out << c.err;
  EXPECT_NE(c.err.find("--good"), std::string::npos) << c.err;
}

TEST(HistoryTool, AMissingScriptIsNamed) {
  const fs::path dir = fresh_dir("history_tool_missing");
  const Command c = mcfbench("history detect", dir, "MCFBENCH_HISTORY_SCRIPT=/nonexistent/h.py ");
  EXPECT_EQ(c.status, 1);
  EXPECT_NE(c.err.find("/nonexistent/h.py"), std::string::npos) << c.err;
  EXPECT_EQ(history_script().find("reports/perf_history.py") != std::string::npos ||
                std::getenv("MCFBENCH_HISTORY_SCRIPT"),
            true);
}

}  // namespace
}  // namespace mcf
