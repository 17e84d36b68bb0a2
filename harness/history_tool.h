#pragma once
// `mcfbench history ...`: the performance history over commits (store, run, detect, bisect,
// A/B, dashboard) lives in reports/perf_history.py, which drives git worktrees and builds of
// other commits; this hands the arguments to it, so the binary and scripts/history.sh are one
// tool.

#include <string>
#include <vector>

namespace mcf {

/// The script `history` runs: $MCFBENCH_HISTORY_SCRIPT when set, else
/// SOURCE_DIR/reports/perf_history.py of the tree this binary was built from.
std::string history_script();

/// Replaces this process with `/usr/bin/python3 history_script() args...` (its exit status is
/// the command's). Throws, naming the path, when the script is missing or cannot be started.
int run_history_tool(const std::vector<std::string>& args);

}  // namespace mcf
