#pragma once
// Progress of long work on stderr, "step 40/100  12.3 s  left 18.5 s". On a terminal one line is
// rewritten in place ("\r", at most five times a second). Anywhere else (a log file, nohup, a
// Slurm array, CI) a plain line is printed at most once per `line_seconds` (default 60 s,
// environment variable MCFBENCH_PROGRESS_SECONDS): a run of ten minutes leaves a heartbeat with
// its time left in its log, while short runs (tests, CI) print nothing extra.

#include <chrono>
#include <cstdio>
#include <string>

namespace mcf {

/// Seconds between progress lines when stderr is not a terminal: MCFBENCH_PROGRESS_SECONDS if
/// set (a number >= 0; 0 prints every update), else 60. A value that is not such a number
/// throws std::invalid_argument naming the variable.
double progress_line_seconds();

class Progress {
 public:
  enum class Mode {
    automatic,  ///< terminal when `out` is a terminal, else lines
    terminal,   ///< one line rewritten in place
    lines,      ///< a plain line at most every line_seconds
  };

  /// line_seconds: from progress_line_seconds(), read by the caller before it writes anything.
  Progress(std::string what, long long total, double line_seconds, Mode mode = Mode::automatic,
           std::FILE* out = stderr);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  void update(long long done, const std::string& extra = "");
  /// update() at `seconds` after construction (tests drive the clock through it).
  void update_at(double seconds, long long done, const std::string& extra = "");
  /// Terminal: ends the line, which stays. Lines: nothing (the caller prints its own summary).
  void finish();
  /// Terminal: erases the line (a caller's summary line takes its place). Lines: nothing.
  void clear();

 private:
  void print(double seconds, long long done, const std::string& extra);

  std::string what_;
  long long total_;
  bool terminal_;
  std::FILE* out_;
  double line_seconds_;
  bool open_ = false;  ///< terminal: a line is on screen and not yet ended
  double last_ = 0.0;  ///< when the last line was printed (seconds after construction)
  std::chrono::steady_clock::time_point start_;
};

}  // namespace mcf
