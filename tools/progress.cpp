#include "tools/progress.h"

#include <cstdio>
#include <unistd.h>

namespace mcf {

Progress::Progress(std::string what, long long total)
    : what_(std::move(what)), total_(total), enabled_(::isatty(2) != 0),
      start_(std::chrono::steady_clock::now()), last_(start_) {}

Progress::~Progress() { finish(); }

void Progress::update(long long done, const std::string& extra) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  if (done < total_ && now - last_ < std::chrono::milliseconds(200)) return;
  last_ = now;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double left = done > 0 ? elapsed * double(total_ - done) / double(done) : 0.0;
  std::fprintf(stderr, "\r%s %lld/%lld  %.1f s  left %.1f s  %s\033[K", what_.c_str(), done, total_, elapsed, left,
               extra.c_str());
  std::fflush(stderr);
}

void Progress::finish() {
  if (enabled_ && !finished_) std::fputc('\n', stderr);
  finished_ = true;
}

}  // namespace mcf
