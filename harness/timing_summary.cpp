#include "harness/timing_summary.h"

#include "harness/json_path.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace mcf {
namespace {

/// The number at a dotted path of each step record, in step order.
std::vector<double> step_values(const nlohmann::json& result, const std::string& path) {
  std::vector<double> values;
  if (!result.contains("steps") || !result["steps"].is_array()) return values;
  for (const auto& s : result["steps"])
    if (const nlohmann::json* v = json_at_path(s, path); v && v->is_number())
      values.push_back(v->get<double>());
  return values;
}

double median_after_first(std::vector<double> values) {
  if (values.size() > 1) values.erase(values.begin());
  if (values.empty()) return NAN;
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

}  // namespace

double median_after_first_step(const nlohmann::json& result, const std::string& path) {
  return median_after_first(step_values(result, path));
}

nlohmann::json timing_summary(const nlohmann::json& result) {
  nlohmann::json out = nlohmann::json::object();
  const std::vector<double> totals = step_values(result, "seconds.total");
  if (totals.empty()) return out;
  double setup = 0;
  if (const nlohmann::json* s = json_at_path(result, "system.setup_seconds.total");
      s && s->is_number())
    setup = s->get<double>();
  double flow = setup;
  for (double t : totals) flow += t;
  out["step_median_seconds"] = median_after_first(totals);
  out["steps_timed"] = totals.size() > 1 ? totals.size() - 1 : totals.size();
  out["first_step_seconds"] = totals.front();
  out["setup_seconds"] = setup;
  out["flow_seconds"] = flow;
  return out;
}

}  // namespace mcf
