#include "flows/planted_slowdown.h"

#include <cstdlib>
#include <stdexcept>
#include <string>

namespace mcf {

namespace {

double parse_planted_slowdown() {
  const char* text = std::getenv("MCFBENCH_PLANTED_SLOWDOWN");
  if (!text || !*text) return 0;
  char* end = nullptr;
  const double f = std::strtod(text, &end);
  if (*end != '\0' || !(f >= 0 && f <= 10))
    throw std::invalid_argument(std::string("MCFBENCH_PLANTED_SLOWDOWN=") + text +
                                ": expected a fraction of the step time in [0, 10], e.g. 0.3");
  return f;
}

}  // namespace

double planted_slowdown() {
  static const double f = parse_planted_slowdown();
  return f;
}

void plant_slowdown(std::chrono::steady_clock::time_point step_start) {
  const double f = planted_slowdown();
  if (f <= 0) return;
  using Clock = std::chrono::steady_clock;
  const auto worked = Clock::now() - step_start;
  const auto until = step_start + worked + std::chrono::duration_cast<Clock::duration>(worked * f);
  // A busy wait, not a sleep: the delay is held on a core as the step's own work is, and a
  // sleep's wake-up on a loaded machine would add its own noise.
  while (Clock::now() < until) {
  }
}

}  // namespace mcf
