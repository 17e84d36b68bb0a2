#pragma once
// The runner reaches the metrics of bench/metrics.h only through these hooks, so the runner
// builds and is testable on its own (tests plug in cheap fakes) and the metrics
// implementation can change without touching it. By default the hooks are the functions of
// bench/metrics.h when this build has their implementation (bench/metrics*.cpp present: CMake
// defines MCFBENCH_HAVE_METRICS), and empty otherwise: asking for a metric whose hook is empty
// is a config error before anything runs.

#include "bench/metrics.h"

#include <functional>

namespace mcf {

struct MetricHooks {
  std::function<MeshDistance(const TriangleMesh& a, const TriangleMesh& b, long long samples)>
      mesh_distance;
  std::function<double(const TriangleMesh& initial, const Positions& current)>
      quasi_conformal_error;
  std::function<double(const Positions& vertices, const Triangles& faces)> sphericity;
};

/// The hooks in use (the defaults until set_metric_hooks is called).
const MetricHooks& metric_hooks();
void set_metric_hooks(MetricHooks hooks);
/// The bench/metrics.h functions, or empty hooks in a build without them.
MetricHooks default_metric_hooks();

}  // namespace mcf
