// The extension rows from the outside: the example solver of examples/ runs through `flow`, `run`
// and `expand` without an edit to config/, flows/, harness/ or tools/, and the option table of
// docs/flow.md, `mcfbench flow --help` and the config reader agree with the schema they are made
// from.

#include "config/config_reader.h"
#include "config/config_schema.h"
#include "config/flow_config.h"
#include "datasets/mesh_io.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace mcf {
namespace {

namespace fs = std::filesystem;

fs::path temp_dir() {
  static const fs::path dir = [] {
    fs::path d = fs::temp_directory_path() / ("mcfbench_rows_" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

/// Runs `mcfbench ARGS`, stdout into `out`; the exit status.
int mcfbench(const std::string& args, const fs::path& out) {
  const std::string cmd = std::string(MCFBENCH_BINARY) + " " + args + " >" + out.string() + " 2>" +
                          (temp_dir() / "stderr.txt").string();
  const int raw = std::system(cmd.c_str());
  return WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
}

std::string text_of(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(ExampleSolver, DampedJacobiFlowMatchesCholmod) {
  // A small step: damped Jacobi converges to 1e-13 well within the cap, so both solvers solve
  // the same systems to far below the 1e-9 compared.
  const std::string flow =
      "flow --mesh icosphere:level=2 --dt 1e-4 --steps 3 --tolerance 1e-13 "
      "--max-iterations 20000 --solver ";
  const fs::path jacobi = temp_dir() / "jacobi", cholmod = temp_dir() / "cholmod";
  ASSERT_EQ(mcfbench(flow + "damped-jacobi --out " + jacobi.string(), temp_dir() / "o1"), 0)
      << text_of(temp_dir() / "stderr.txt");
  ASSERT_EQ(mcfbench(flow + "cholmod --out " + cholmod.string(), temp_dir() / "o2"), 0);
  const TriangleMesh a = read_mesh((jacobi / "final.ply").string());
  const TriangleMesh b = read_mesh((cholmod / "final.ply").string());
  ASSERT_EQ(a.vertices.rows(), b.vertices.rows());
  EXPECT_LT((a.vertices - b.vertices).cwiseAbs().maxCoeff(), 1e-9);
  // The flow moved the surface: the comparison is not between two unmoved meshes.
  const nlohmann::json result = nlohmann::json::parse(text_of(jacobi / "result.json"));
  EXPECT_EQ(result["solver_name"], "damped-jacobi");
  EXPECT_EQ(result["config"]["solver"]["name"], "damped-jacobi");
  EXPECT_LT(result["steps"].back()["area"].get<double>(), result["mesh"]["area"].get<double>());
  EXPECT_GT(result["steps"].back()["solver"]["iterations"].get<int>(), 1);
}

// The example's own options (examples/damped_jacobi.cpp: solver.omega, solver.check_every), kept
// in SolverConfig::params with nothing in config/ naming them: taken, recorded where the solver
// runs, at their one default otherwise, and refused under another solver.
TEST(ExampleSolver, OwnOptionsAreTakenRecordedAndRefusedElsewhere) {
  const std::string flow =
      "flow --mesh icosphere:level=2 --dt 1e-4 --steps 3 --tolerance 1e-13 "
      "--max-iterations 20000 --solver ";
  const fs::path tuned = temp_dir() / "tuned", plain = temp_dir() / "plain",
                 cholmod = temp_dir() / "cholmod_only";
  ASSERT_EQ(mcfbench(flow + "damped-jacobi --omega 0.5 --check-every 4 --out " + tuned.string(),
                     temp_dir() / "o1"),
            0)
      << text_of(temp_dir() / "stderr.txt");
  ASSERT_EQ(mcfbench(flow + "damped-jacobi --out " + plain.string(), temp_dir() / "o2"), 0);
  ASSERT_EQ(mcfbench(flow + "cholmod --out " + cholmod.string(), temp_dir() / "o3"), 0);
  const nlohmann::json t = nlohmann::json::parse(text_of(tuned / "result.json"));
  const nlohmann::json p = nlohmann::json::parse(text_of(plain / "result.json"));
  const nlohmann::json c = nlohmann::json::parse(text_of(cholmod / "result.json"));
  EXPECT_EQ(t["config"]["solver"]["omega"], 0.5);
  EXPECT_EQ(t["config"]["solver"]["check_every"], 4);
  EXPECT_EQ(p["config"]["solver"]["omega"], 2.0 / 3.0);
  EXPECT_EQ(p["config"]["solver"]["check_every"], 1);
  EXPECT_FALSE(c["config"]["solver"].contains("omega"));
  // Both solve the same systems (to 1e-13): the same flow as CHOLMOD's; checked every 4th
  // sweep, every step's sweeps are a multiple of 4.
  const TriangleMesh a = read_mesh((tuned / "final.ply").string());
  const TriangleMesh b = read_mesh((cholmod / "final.ply").string());
  EXPECT_LT((a.vertices - b.vertices).cwiseAbs().maxCoeff(), 1e-9);
  for (const auto& step : t["steps"]) EXPECT_EQ(step["solver"]["iterations"].get<int>() % 4, 0);
  // Another damping takes another number of sweeps.
  EXPECT_NE(t["steps"][0]["solver"]["iterations"], p["steps"][0]["solver"]["iterations"]);
  // Under another solver: refused, naming the key, its solver and the one in use.
  EXPECT_NE(mcfbench(flow + "cholmod --omega 0.5 --out " + (temp_dir() / "no").string(),
                     temp_dir() / "o4"),
            0);
  EXPECT_NE(text_of(temp_dir() / "stderr.txt")
                .find("solver.omega: applies to solver \"damped-jacobi\" only, the solver is "
                      "\"cholmod\""),
            std::string::npos)
      << text_of(temp_dir() / "stderr.txt");
  EXPECT_FALSE(fs::exists(temp_dir() / "no" / "result.json"));
}

TEST(ExampleSolver, RunsThroughExpandAndRun) {
  const fs::path config = temp_dir() / "matrix.json";
  std::ofstream(config) << R"({"name": "rows", "defaults": {"mesh": "icosphere:level=1",
      "steps": 1, "dt": 1e-4}, "axes": {"solver.name": ["cholmod", "damped-jacobi"]}})";
  const fs::path listing = temp_dir() / "expand.txt";
  ASSERT_EQ(mcfbench("expand " + config.string(), listing), 0);
  EXPECT_NE(text_of(listing).find("damped-jacobi"), std::string::npos) << text_of(listing);
  ASSERT_EQ(mcfbench("run " + config.string() + " --out " + (temp_dir() / "run").string(),
                     temp_dir() / "run.txt"),
            0)
      << text_of(temp_dir() / "stderr.txt");
}

TEST(FlowOptions, HelpListsEveryFlagOfTheSchema) {
  const fs::path help = temp_dir() / "help.txt";
  ASSERT_EQ(mcfbench("flow --help", help), 0);
  const std::string text = text_of(help);
  for (const OptionSpec& o : flow_config_schema()) {
    if (!o.flag.empty()) {
      EXPECT_NE(text.find(o.flag + " "), std::string::npos) << o.flag;
    }
  }
  // The example solver's row reaches the help of the binary it is built into.
  EXPECT_NE(text.find("damped-jacobi"), std::string::npos);
}

TEST(FlowOptions, TheReaderTakesEveryKeyAndRecordsOnlySchemaKeys) {
  // Every option at its default, written by key: accepted, and read back as the default config.
  nlohmann::json j;
  for (const OptionSpec& o : flow_config_schema()) {
    const auto [parent, leaf] = split_key(o.key);
    (parent.empty() ? j : j[parent])[leaf] = o.fallback;
  }
  j["mesh"] = "icosphere:level=1";
  // -1 (the solver's) is a default, not a value one may write.
  j["solver"].erase("tolerance");
  j["octree"].erase("stabilization_weight");
  FlowConfig c;
  ASSERT_NO_THROW(c = flow_config_from_json(j, "test")) << j.dump();
  // Every key to_json records is one of the schema's.
  const nlohmann::json recorded = to_json(c);
  for (const auto& [key, value] : recorded.items()) {
    if (value.is_object()) {
      for (const auto& [leaf, v] : value.items()) {
        bool found = false;
        for (const OptionSpec& o : flow_config_schema()) found |= o.key == key + "." + leaf;
        EXPECT_TRUE(found) << key << "." << leaf;
      }
    } else {
      bool found = false;
      for (const OptionSpec& o : flow_config_schema()) found |= o.key == key;
      EXPECT_TRUE(found) << key;
    }
  }
  j["solver"]["no_such_key"] = 1;
  EXPECT_THROW(flow_config_from_json(j, "test"), ConfigError);
}

TEST(FlowOptions, DocsTableIsTheSchemas) {
  // docs/flow.md holds the table between two markers; MCFBENCH_UPDATE_DOCS=1 rewrites it.
  const fs::path page = fs::path(MCFBENCH_SOURCE_DIR) / "docs" / "flow.md";
  const std::string begin =
      "<!-- flow options: generated from the rows (tests/tools/"
      "test_extension_rows.cpp rewrites it with MCFBENCH_UPDATE_DOCS=1) -->\n";
  const std::string end = "<!-- end of flow options -->\n";
  std::string text = text_of(page);
  const std::size_t a = text.find(begin), b = text.find(end);
  ASSERT_NE(a, std::string::npos) << "docs/flow.md lacks the marker " << begin;
  ASSERT_NE(b, std::string::npos);
  const std::string table = flow_options_markdown();
  if (std::getenv("MCFBENCH_UPDATE_DOCS")) {
    text.replace(a + begin.size(), b - a - begin.size(), table);
    std::ofstream(page) << text;
  }
  EXPECT_EQ(text.substr(a + begin.size(), b - a - begin.size()), table)
      << "docs/flow.md's option table differs from the rows; rerun this test with "
         "MCFBENCH_UPDATE_DOCS=1 to rewrite it";
}

}  // namespace
}  // namespace mcf
