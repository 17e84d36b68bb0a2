#include "harness/progress.h"

#include <unistd.h>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

namespace mcf {

double progress_line_seconds() {
  const char* text = std::getenv("MCFBENCH_PROGRESS_SECONDS");
  if (text == nullptr || *text == '\0') return 60.0;
  char* end = nullptr;
  const double seconds = std::strtod(text, &end);
  if (*end != '\0' || !std::isfinite(seconds) || seconds < 0)
    throw std::invalid_argument(
        std::string("MCFBENCH_PROGRESS_SECONDS: expected seconds >= 0, got '") + text + "'");
  return seconds;
}

Progress::Progress(std::string what, long long total, double line_seconds, Mode mode,
                   std::FILE* out)
    : what_(std::move(what)),
      total_(total),
      terminal_(mode == Mode::terminal ||
                (mode == Mode::automatic && ::isatty(::fileno(out)) != 0)),
      out_(out),
      line_seconds_(line_seconds),
      start_(std::chrono::steady_clock::now()) {}

Progress::~Progress() {
  finish();
}

void Progress::update(long long done, const std::string& extra) {
  update_at(std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(), done,
            extra);
}

void Progress::update_at(double seconds, long long done, const std::string& extra) {
  if (terminal_) {
    // The last update always shows, so the line ends on "total/total".
    if (done < total_ && open_ && seconds - last_ < 0.2) return;
  } else if (done >= total_ || seconds - last_ < line_seconds_) {
    return;  // the caller reports completion itself; a line only when line_seconds have passed
  }
  last_ = seconds;
  print(seconds, done, extra);
}

void Progress::print(double seconds, long long done, const std::string& extra) {
  const double left = done > 0 ? seconds * double(total_ - done) / double(done) : 0.0;
  std::fprintf(out_, "%s%s %lld/%lld  %.1f s  left %.1f s%s%s%s", terminal_ ? "\r" : "",
               what_.c_str(), done, total_, seconds, left, extra.empty() ? "" : "  ", extra.c_str(),
               terminal_ ? "\033[K" : "\n");
  std::fflush(out_);
  open_ = terminal_;
}

void Progress::finish() {
  if (open_) std::fputc('\n', out_);
  open_ = false;
}

void Progress::clear() {
  if (open_) {
    std::fputs("\r\033[K", out_);
    std::fflush(out_);
  }
  open_ = false;
}

}  // namespace mcf
