// Progress lines: rewritten in place on a terminal, a plain line at most every line_seconds
// elsewhere (so a long run's log shows where it is, a short one's shows nothing extra).

#include "harness/progress.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace mcf {
namespace {

/// What a Progress wrote into an in-memory FILE.
struct Captured {
  char* data = nullptr;
  std::size_t size = 0;
  std::FILE* file = open_memstream(&data, &size);
  ~Captured() {
    if (file) std::fclose(file);
    std::free(data);
  }
  std::string text() {
    std::fflush(file);
    return std::string(data, size);
  }
};

TEST(Progress, LinesModePrintsAHeartbeatOnlyEveryLineSecondsAndNotAtTheEnd) {
  Captured out;
  {
    Progress p("step", 100, 60.0, Progress::Mode::lines, out.file);
    p.update_at(1.0, 1);
    p.update_at(59.9, 10);
    EXPECT_EQ(out.text(), "");  // a short run prints nothing
    p.update_at(60.0, 20);
    EXPECT_EQ(out.text(), "step 20/100  60.0 s  left 240.0 s\n");
    p.update_at(100.0, 30);  // 40 s after the last line
    p.update_at(120.5, 40, "cycle 2");
    p.update_at(300.0, 100);  // the caller reports completion itself
    p.finish();
  }
  EXPECT_EQ(out.text(),
            "step 20/100  60.0 s  left 240.0 s\nstep 40/100  120.5 s  left 180.8 s  cycle 2\n");
}

TEST(Progress, LinesModeWithZeroSecondsPrintsEveryUpdateButTheLast) {
  Captured out;
  Progress p("cell 3 step", 3, 0.0, Progress::Mode::lines, out.file);
  for (int step = 0; step <= 3; ++step) p.update_at(step * 2.0, step);
  EXPECT_EQ(out.text(),
            "cell 3 step 0/3  0.0 s  left 0.0 s\n"
            "cell 3 step 1/3  2.0 s  left 4.0 s\n"
            "cell 3 step 2/3  4.0 s  left 2.0 s\n");
}

TEST(Progress, TerminalModeRewritesOneLineThrottledAndEndsOrErasesIt) {
  Captured out;
  {
    Progress p("step", 10, 60.0, Progress::Mode::terminal, out.file);
    p.update_at(0.0, 1);
    p.update_at(0.1, 2);  // within 0.2 s of the last: skipped
    p.update_at(0.5, 5);
    p.update_at(0.55, 10);  // the last always shows
    p.finish();
  }
  EXPECT_EQ(out.text(),
            "\rstep 1/10  0.0 s  left 0.0 s\033[K"
            "\rstep 5/10  0.5 s  left 0.5 s\033[K"
            "\rstep 10/10  0.6 s  left 0.0 s\033[K\n");
  Captured erased;
  {
    Progress p("step", 10, 60.0, Progress::Mode::terminal, erased.file);
    p.update_at(0.0, 1);
    p.clear();  // the caller's summary line takes its place; the destructor adds nothing
  }
  EXPECT_EQ(erased.text(), "\rstep 1/10  0.0 s  left 0.0 s\033[K\r\033[K");
}

TEST(Progress, LineSecondsComeFromTheEnvironmentAndABadValueNamesTheVariable) {
  ::unsetenv("MCFBENCH_PROGRESS_SECONDS");
  EXPECT_EQ(progress_line_seconds(), 60.0);
  ::setenv("MCFBENCH_PROGRESS_SECONDS", "2.5", 1);
  EXPECT_EQ(progress_line_seconds(), 2.5);
  for (const char* bad : {"-1", "soon", "5s", "inf"}) {
    ::setenv("MCFBENCH_PROGRESS_SECONDS", bad, 1);
    try {
      progress_line_seconds();
      ADD_FAILURE() << bad << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("MCFBENCH_PROGRESS_SECONDS"), std::string::npos)
          << e.what();
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    }
  }
  ::unsetenv("MCFBENCH_PROGRESS_SECONDS");
}

}  // namespace
}  // namespace mcf
