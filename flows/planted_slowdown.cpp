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

PlantedPhase parse_planted_phase() {
  const char* text = std::getenv("MCFBENCH_PLANTED_PHASE");
  if (!text || !*text || std::string(text) == "step") return PlantedPhase::step;
  if (std::string(text) == "update") return PlantedPhase::update;
  throw std::invalid_argument(std::string("MCFBENCH_PLANTED_PHASE=") + text +
                              ": expected step or update");
}

}  // namespace

double planted_slowdown() {
  static const double f = parse_planted_slowdown();
  return f;
}

PlantedPhase planted_phase() {
  static const PlantedPhase p = parse_planted_phase();
  return p;
}

const char* to_string(PlantedPhase phase) {
  return phase == PlantedPhase::update ? "update" : "step";
}

double plant_slowdown(PlantedPhase phase, std::chrono::steady_clock::time_point start) {
  const double f = planted_slowdown();
  if (f <= 0 || phase != planted_phase()) return 0;
  using Clock = std::chrono::steady_clock;
  const auto reached = Clock::now();
  const auto until = reached + std::chrono::duration_cast<Clock::duration>((reached - start) * f);
  // A busy wait, not a sleep: the delay is held on a core as the phase's own work is, and a
  // sleep's wake-up on a loaded machine would add its own noise.
  while (Clock::now() < until) {
  }
  return std::chrono::duration<double>(Clock::now() - reached).count();
}

}  // namespace mcf
