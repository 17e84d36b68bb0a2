// mcfbench: run mean-curvature flows, experiment matrices and reports (see README.md).

#include "tools/commands.h"

#include <cstdio>
#include <exception>

int main(int argc, char** argv) {
  CLI::App app{
      "mcfbench — a benchmark harness for fast mean-curvature flow on triangle meshes\n"
      "(Chuang & Kazhdan 2011 octree finite elements, cMCF, higher-order time stepping).\n"
      "Run `mcfbench SUBCOMMAND --help` for the options of each subcommand."};
  app.require_subcommand(1);
  std::function<int()> run;
  mcf::add_flow_command(app, run);
  mcf::add_mesh_info_command(app, run);
  mcf::add_run_command(app, run);
  mcf::add_submit_command(app, run);
  mcf::add_expand_command(app, run);
  mcf::add_collect_command(app, run);
  mcf::add_compare_command(app, run);
  mcf::add_history_command(app, run);
  mcf::add_distance_command(app, run);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    return run ? run() : 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mcfbench: error: %s\n", e.what());
    return 1;
  }
}
