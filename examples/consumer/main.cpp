// Mean-curvature flow of a sphere through the installed library, stopped by its callback once
// the radius has halved; prints the steps run and the final mean radius.
#include <mcfbench/mcfbench.h>

#include <cstdio>

int main() {
  mcfbench::Options options;
  options.set("mesh", "icosphere:level=4").set("dt", 1e-2).set("steps", 100).set("threads", 1);
  int steps = 0;
  const mcfbench::FlowResult r = mcfbench::flow(options, [&](const mcfbench::Step& s) {
    steps = s.step;
    return s.vertices.rowwise().norm().mean() < 0.5;  // true ends the flow
  });
  std::printf("%d steps, mean radius %.6f\n", steps, r.vertices.rowwise().norm().mean());
}
