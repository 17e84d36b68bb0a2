#pragma once
// `mcfbench distance A B`: the Metro-style distance between two surfaces (harness/metrics.h) as a
// JSON report.

#include <nlohmann/json.hpp>

#include <cstdint>
#include <string>

namespace mcf {

/// {a, b, rms_forward, max_forward, rms_backward, max_backward, rms, max, samples, seed,
/// seconds} for the surfaces a and b: an existing file is read as is (no unit-cube scaling:
/// comparing a flow's output with its reference must not rescale either), anything else is a
/// mesh spec (generators, cgal:..., @faces). `seconds` times the distance alone.
nlohmann::json surface_distance(const std::string& a, const std::string& b, long long samples,
                                std::uint64_t seed);

}  // namespace mcf
