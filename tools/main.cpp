// mcfbench: run mean-curvature flows, experiment matrices and reports (see README.md).

#include "tools/commands.h"

#include <cstdio>
#include <exception>
#include <string>

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
  // The first word that is not an option names the subcommand (the app itself takes no option
  // with a value). CLI11 would answer an unknown one with "A subcommand is required", and with
  // --help after it print the main help and exit 0: name it instead, and fail.
  for (int i = 1; i < argc; ++i) {
    const std::string word = argv[i];
    if (!word.empty() && word[0] == '-') continue;
    bool known = false;
    std::string names;
    const CLI::App& registered = app;
    for (const CLI::App* sub : registered.get_subcommands([](const CLI::App*) { return true; })) {
      known = known || sub->get_name() == word;
      names += (names.empty() ? "" : ", ") + sub->get_name();
    }
    if (!known)
      return app.exit(
          CLI::ParseError("unknown subcommand '" + word + "' (subcommands: " + names + ")",
                          CLI::ExitCodes::ExtrasError));
    break;
  }
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
