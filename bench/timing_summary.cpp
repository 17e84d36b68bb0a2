#include "bench/timing_summary.h"

#include <algorithm>
#include <vector>

namespace mcf {

nlohmann::json timing_summary(const nlohmann::json& result) {
  nlohmann::json out = nlohmann::json::object();
  if (!result.contains("steps") || !result["steps"].is_array()) return out;
  std::vector<double> totals;
  for (const auto& s : result["steps"]) {
    const auto* t = s.contains("seconds") ? &s["seconds"] : nullptr;
    if (t && t->contains("total") && (*t)["total"].is_number())
      totals.push_back((*t)["total"].get<double>());
  }
  if (totals.empty()) return out;
  double setup = 0;
  if (result.contains("system") && result["system"].contains("setup_seconds") &&
      result["system"]["setup_seconds"].contains("total"))
    setup = result["system"]["setup_seconds"]["total"].get<double>();
  std::vector<double> later(totals.size() > 1 ? totals.begin() + 1 : totals.begin(), totals.end());
  std::sort(later.begin(), later.end());
  const std::size_t n = later.size();
  const double median = n % 2 ? later[n / 2] : 0.5 * (later[n / 2 - 1] + later[n / 2]);
  double flow = setup;
  for (double t : totals) flow += t;
  out["step_median_seconds"] = median;
  out["steps_timed"] = n;
  out["first_step_seconds"] = totals.front();
  out["setup_seconds"] = setup;
  out["flow_seconds"] = flow;
  return out;
}

}  // namespace mcf
