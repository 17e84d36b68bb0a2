#pragma once
// A known slowdown planted in every flow step, to check that the performance gate and the
// history find one (scripts/history_aa_ab.sh): with $MCFBENCH_PLANTED_SLOWDOWN = f each step
// busy-waits until it has lasted (1 + f) times its own work, so its recorded seconds.total is
// (1 + f) times the step's. A result records f (environment.planted_slowdown), so a planted run
// can never pass for a measurement of the code. Unset or 0: nothing is added.

#include <chrono>

namespace mcf {

/// f of $MCFBENCH_PLANTED_SLOWDOWN (0 when unset or empty), read once. Throws
/// std::invalid_argument naming the variable when it is not a number in [0, 10].
double planted_slowdown();

/// Inputs:
///   step_start  when the step began (steady clock)
/// With f = planted_slowdown() > 0, returns only once (1 + f) times the time from step_start to
/// the call has passed since step_start; with f = 0, at once.
void plant_slowdown(std::chrono::steady_clock::time_point step_start);

}  // namespace mcf
