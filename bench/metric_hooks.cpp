#include "bench/metric_hooks.h"

namespace mcf {
namespace {

MetricHooks& current() {
  static MetricHooks hooks = default_metric_hooks();
  return hooks;
}

}  // namespace

MetricHooks default_metric_hooks() {
  MetricHooks h;
#ifdef MCFBENCH_HAVE_METRICS
  h.mesh_distance = [](const TriangleMesh& a, const TriangleMesh& b, long long samples) {
    return mesh_distance(a, b, samples);
  };
  h.quasi_conformal_error = [](const TriangleMesh& initial, const Positions& current) {
    return quasi_conformal_error(initial, current);
  };
  h.sphericity = [](const Positions& v, const Triangles& f) { return sphericity(v, f); };
#endif
  return h;
}

const MetricHooks& metric_hooks() {
  return current();
}

void set_metric_hooks(MetricHooks hooks) {
  current() = std::move(hooks);
}

}  // namespace mcf
