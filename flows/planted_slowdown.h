#pragma once
// A known slowdown planted in the flow, to check that the performance gate and the history find
// one (scripts/history_aa_ab.sh). With $MCFBENCH_PLANTED_SLOWDOWN = f the planted phase
// busy-waits until it has lasted (1 + f) times its own work. $MCFBENCH_PLANTED_PHASE picks the
// phase: `step` (the default: the whole step, so its seconds.total grows (1 + f)-fold) or
// `update` (the basis update only: the octree's re-integration, or its rebuild, and the hat
// basis's assembly; seconds.update grows (1 + f)-fold and the step by f times the update's
// share). A result records both (environment.planted_slowdown, environment.planted_phase), so a
// planted run can never pass for a measurement of the code. Unset or 0: nothing is added.

#include <chrono>

namespace mcf {

enum class PlantedPhase { step, update };

/// f of $MCFBENCH_PLANTED_SLOWDOWN (0 when unset or empty), read once. Throws
/// std::invalid_argument naming the variable when it is not a number in [0, 10].
double planted_slowdown();

/// The phase of $MCFBENCH_PLANTED_PHASE (step when unset or empty), read once. Throws
/// std::invalid_argument naming the variable when it is neither `step` nor `update`.
PlantedPhase planted_phase();
const char* to_string(PlantedPhase phase);

/// Inputs:
///   phase  the phase that calls (the step at its end, the update after each basis update)
///   start  when that phase's work began (steady clock)
/// With f = planted_slowdown() > 0 and phase = planted_phase(), returns only once (1 + f) times
/// the time from start to the call has passed since start; otherwise at once.
/// Returns the seconds it added (0 when it added none), which a planted run records.
double plant_slowdown(PlantedPhase phase, std::chrono::steady_clock::time_point start);

}  // namespace mcf
