#include "config/flow_registry.h"

namespace mcf {

const NamedTable<FlowRow>& flow_table() {
  static const NamedTable<FlowRow> t = [] {
    NamedTable<FlowRow> f("flow");
    f.add({"mcf", "mean-curvature flow: M and K at every step", false, false, ""});
    f.add({"cmcf", "conformalized MCF: the stiffness of t=0 kept", false, true,
           "cmcf keeps the stiffness of t=0, which needs a fixed basis; the rebuilt octree "
           "changes its functions every step (use octree.tracking \"tracked\" or basis \"hat\")"});
    f.add({"heat", "heat flow: both operators of t=0 kept", true, true,
           "heat flow keeps the operators of t=0, which needs a fixed basis; the rebuilt "
           "octree changes its functions every step"});
    return f;
  }();
  return t;
}

const FlowRow& flow_row(const std::string& name) {
  return flow_table().at(name);
}

}  // namespace mcf
