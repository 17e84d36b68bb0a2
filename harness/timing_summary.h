#pragma once
// One flow's time as the studies compare it: a repetition's sample is the median step time over
// steps 2..N (step 1 carries first-touch costs a later step does not: page faults, the first
// numeric factorization, a hierarchy's first Galerkin products), with the set-up apart and the
// whole flow's time beside it.

#include <nlohmann/json.hpp>

#include <string>

namespace mcf {

/// The median over steps 2..N (step 1 when it is the only one) of the number at `path` in each
/// step record (e.g. "seconds.total", "seconds.solve"); NaN when no step has it. One
/// repetition's sample for `compare` and the studies.
double median_after_first_step(const nlohmann::json& result, const std::string& path);

/// From a flow result (steps[i].seconds.total, system.setup_seconds.total): {"step_median_seconds"
/// (steps 2..N; step 1 when it is the only one), "steps_timed", "first_step_seconds",
/// "setup_seconds", "flow_seconds" (set-up plus every step)}. An empty object for a result
/// without timed steps.
nlohmann::json timing_summary(const nlohmann::json& result);

}  // namespace mcf
