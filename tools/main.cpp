// mcfbench: run mean-curvature flows, experiment matrices and reports (see README.md).

#include "tools/commands.h"

#include "config/config_reader.h"
#include "distributed/comm.h"
#include "solvers/petsc_runtime.h"

#include <cstdio>
#include <exception>
#include <stdexcept>
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
  } catch (const mcf::dist::RankFailure&) {
    return 1;  // rank 0 has said why (distributed/comm.h)
  } catch (const std::exception& e) {
    // Under mpirun every rank reads the same config and meets the same error in it: rank 0
    // alone says so, so that a bad input gives one message.
    const bool everyone = dynamic_cast<const mcf::ConfigError*>(&e) != nullptr ||
                          dynamic_cast<const std::invalid_argument*>(&e) != nullptr;
    if (!everyone || mcf::launched_rank() == 0)
      std::fprintf(stderr, "mcfbench: error: %s\n", e.what());
    return 1;
  }
}
