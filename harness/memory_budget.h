#pragma once
// How much memory a flow may use, and the check that refuses one whose estimated peak
// (config/memory_estimate.h) does not fit, before its mesh is generated or its basis built.
//
// By default the budget is the memory available now: the kernel's MemAvailable, or less where the
// process's control group (a Slurm job's `--mem`, a container's limit) has less room left. A
// `--max-memory SIZE` budget replaces it (a node shared by agreement, an estimate known to be
// pessimistic); `--max-memory none` turns the check off.

#include "config/flow_config.h"
#include "config/memory_estimate.h"

#include <nlohmann/json.hpp>

#include <stdexcept>
#include <string>

namespace mcf {

struct MemoryBudget {
  double bytes = -1;   ///< < 0: no limit
  bool total = false;  ///< true: the flow's whole estimate must fit (--max-memory); false: what it
                       ///< adds to the process's resident memory must fit into what is available
  std::string source;  ///< what set it, for messages and result.json
  nlohmann::json to_json() const;
};

/// The flow does not fit: the message names what was asked, the estimate and the budget.
struct MemoryLimitError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// "8G", "8GiB", "1.5g", "512M", "300k", "123456789" (bytes; K/M/G/T are powers of 1024).
/// Throws std::invalid_argument naming `what` (the flag) for anything else.
double parse_memory_size(const std::string& text, const std::string& what);

/// The budget for `--max-memory` as given: "" = the memory available now, "none" = no limit,
/// else parse_memory_size.
MemoryBudget memory_budget(const std::string& max_memory);

/// The memory available to this process now: min(MemAvailable of /proc/meminfo, room left in its
/// memory control group, v2 or v1); `source` says which. -1 where neither can be read.
double available_memory_bytes(std::string* source = nullptr);
/// MemAvailable of a /proc/meminfo text, in bytes; -1 without the line.
double mem_available_from_meminfo(const std::string& text);

/// This process's resident memory now (VmRSS), in bytes; 0 where it cannot be read.
double resident_memory_bytes();

/// The estimate of `config`'s flow on a mesh of `sizes` with the process's resident memory now,
/// checked against `budget`: returned when it fits, else MemoryLimitError naming `what`.
MemoryEstimate checked_memory_estimate(const FlowConfig& config, const FlowSizes& sizes,
                                       const MemoryBudget& budget, const std::string& what);

/// Throws MemoryLimitError, naming `what` (the mesh spec, the cell), when `estimate` does not fit
/// `budget`.
void check_memory(const MemoryEstimate& estimate, const MemoryBudget& budget,
                  const FlowConfig& config, const std::string& what);

}  // namespace mcf
