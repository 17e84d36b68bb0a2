// Experiment matrix expansion (axes, zip, exclude, repetitions, quick), strict config errors
// naming the file and the key path, shard partition, cell key/hash stability.

#include "config/config_reader.h"
#include "config/multigrid_params.h"
#include "harness/cell_hash.h"
#include "harness/experiment_config.h"
#include "harness/runner.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <set>

namespace mcf {
namespace {

using nlohmann::json;

ExperimentConfig expand(const json& j, bool quick = false) {
  return parse_experiment_config(j, "study.json", quick);
}

std::set<std::string> assignments(const ExperimentConfig& e) {
  std::set<std::string> s;
  for (const auto& c : e.cells) s.insert(c.assignment.dump() + "#" + std::to_string(c.repetition));
  return s;
}

const json base = {{"mesh", "icosphere:level=1"}, {"steps", 2}};

TEST(ExperimentConfig, AxesAreACartesianProductInFixedOrder) {
  const auto e =
      expand({{"defaults", base},
              {"axes", {{"solver.name", {"cholmod", "pcg", "dense"}}, {"dt", {1e-3, 2e-3}}}}});
  ASSERT_EQ(e.cells.size(), 6u);
  EXPECT_EQ(assignments(e).size(), 6u);
  // Axes in sorted key order ("dt" < "solver.name"), the last one fastest.
  EXPECT_EQ(e.cells[0].assignment, (json{{"dt", 1e-3}, {"solver.name", "cholmod"}}));
  EXPECT_EQ(e.cells[1].assignment, (json{{"dt", 1e-3}, {"solver.name", "pcg"}}));
  EXPECT_EQ(e.cells[3].assignment, (json{{"dt", 2e-3}, {"solver.name", "cholmod"}}));
  for (size_t i = 0; i < e.cells.size(); ++i) {
    EXPECT_EQ(e.cells[i].index, int(i));
    // The assignment lands in the full config, defaults filled in.
    EXPECT_EQ(e.cells[i].config["solver"]["name"], e.cells[i].assignment["solver.name"]);
    EXPECT_EQ(e.cells[i].config["steps"], 2);
    EXPECT_EQ(e.cells[i].config["octree"]["depth"], 8);
    EXPECT_EQ(e.cells[i].flow.dt, e.cells[i].assignment["dt"].get<double>());
  }
}

TEST(ExperimentConfig, ZipGroupsVaryTogether) {
  const auto e = expand({{"defaults", base},
                         {"axes", {{"dt", {1e-3, 2e-3}}}},
                         {"zip", json::parse(R"([{"solver.name": ["pcg", "pcg", "cholmod"],
                                                  "solver.preconditioner": ["none", "ichol", "jacobi"]}])")}});
  ASSERT_EQ(e.cells.size(), 6u);  // 2 x 3, not 2 x 3 x 3
  std::set<std::pair<std::string, std::string>> pairs;
  for (const auto& c : e.cells)
    pairs.insert({c.config["solver"]["name"].get<std::string>(),
                  c.config["solver"]["preconditioner"].get<std::string>()});
  EXPECT_EQ(pairs, (std::set<std::pair<std::string, std::string>>{
                       {"pcg", "none"}, {"pcg", "ichol"}, {"cholmod", "jacobi"}}));
  EXPECT_EQ(e.cells[0].assignment.size(), 3u);
}

// A default applies to the cells whose components read it; a row's null leaves a zip's column
// to the defaults; a value a cell's own assignment gives where nothing reads it is refused.
TEST(ExperimentConfig, DefaultsApplyWhereTheyAreReadAndAxisValuesStrictly) {
  json defaults = base;
  defaults["solver.cycles"] = 2;
  defaults["solver.stall_ratio"] = 0;
  defaults["solver.preconditioner"] = "ichol";
  const auto e = expand(
      {{"defaults", defaults}, {"axes", {{"solver.name", {"cholmod", "multigrid", "pcg"}}}}});
  ASSERT_EQ(e.cells.size(), 3u);
  const json& cholmod = e.cells[0].config["solver"];
  const json& multigrid = e.cells[1].config["solver"];
  const json& pcg = e.cells[2].config["solver"];
  EXPECT_EQ(cholmod["cycles"], 1);
  EXPECT_EQ(cholmod["preconditioner"], "jacobi");
  EXPECT_FALSE(cholmod.contains("stall_ratio"));
  EXPECT_EQ(multigrid["cycles"], 2);
  EXPECT_EQ(multigrid["stall_ratio"], 0);
  EXPECT_EQ(multigrid["preconditioner"], "jacobi");
  EXPECT_EQ(pcg["preconditioner"], "ichol");
  EXPECT_EQ(pcg["cycles"], 1);
  EXPECT_EQ(multigrid_options(e.cells[1].flow.solver).cycles, 2);
  EXPECT_EQ(multigrid_options(e.cells[0].flow.solver).cycles, 1);

  // null in a zip row: the defaults' value, applied where it is read.
  const auto z = expand(
      {{"defaults", defaults}, {"zip", json::parse(R"([{"solver.name": ["cholmod", "multigrid"],
                                                  "solver.stall_ratio": [null, 0.5]}])")}});
  ASSERT_EQ(z.cells.size(), 2u);
  EXPECT_EQ(z.cells[0].assignment, (json{{"solver.name", "cholmod"}}));
  EXPECT_FALSE(z.cells[0].config["solver"].contains("stall_ratio"));
  EXPECT_EQ(z.cells[1].config["solver"]["stall_ratio"], 0.5);

  // The cell's own value: refused, naming the cell and the key.
  try {
    expand({{"defaults", base}, {"zip", json::parse(R"([{"solver.name": ["cholmod", "multigrid"],
                                     "solver.cycles": [7, 2]}])")}});
    ADD_FAILURE() << "a cell's solver.cycles with CHOLMOD was taken";
  } catch (const ConfigError& err) {
    const std::string m = err.what();
    EXPECT_NE(m.find("study.json (cell"), std::string::npos) << m;
    EXPECT_NE(m.find("solver.cycles: applies to solver \"multigrid\""), std::string::npos) << m;
  }
}

// A basis's option applies to that basis's cells from any part of the matrix (octree.depth tied
// to the mesh across bases): the hat cells record the default and lose it from their assignment;
// where that leaves two cells alike, the matrix is refused.
TEST(ExperimentConfig, ABasisOptionAppliesToItsBasisCellsFromAnyDimension) {
  const auto e =
      expand({{"defaults", base},
              {"zip", json::parse(R"([{"mesh": ["icosphere:level=1", "icosphere:level=2"],
                                                  "octree.depth": [6, 7]},
                                                 {"basis": ["hat", "octree"]}])")}});
  ASSERT_EQ(e.cells.size(), 4u);
  EXPECT_EQ(e.cells[0].config["basis"], "hat");
  EXPECT_EQ(e.cells[0].config["octree"]["depth"], 8);
  EXPECT_FALSE(e.cells[0].assignment.contains("octree.depth"));
  EXPECT_EQ(e.cells[1].config["octree"]["depth"], 6);
  EXPECT_EQ(e.cells[1].assignment["octree.depth"], 6);
  EXPECT_EQ(e.cells[3].config["octree"]["depth"], 7);
  try {
    expand(
        {{"defaults", base}, {"axes", {{"basis", {"hat", "octree"}}, {"octree.depth", {6, 7}}}}});
    ADD_FAILURE() << "two hat cells alike once octree.depth was dropped were taken";
  } catch (const ConfigError& err) {
    EXPECT_NE(std::string(err.what()).find("study.json"), std::string::npos) << err.what();
  }
}

TEST(ExperimentConfig, ExcludeDropsMatchingCellsIncludingDefaults) {
  const auto e =
      expand({{"defaults", base},
              {"axes", {{"solver.name", {"cholmod", "pcg", "dense"}}, {"dt", {1e-3, 2e-3}}}},
              {"exclude", {{{"solver.name", "pcg"}, {"dt", 2e-3}}, {{"solver.name", "dense"}}}}});
  ASSERT_EQ(e.cells.size(), 3u);  // 6 - 1 - 2
  for (const auto& c : e.cells) {
    EXPECT_NE(c.assignment["solver.name"], "dense");
    EXPECT_FALSE(c.assignment["solver.name"] == "pcg" && c.assignment["dt"] == 2e-3);
  }
  // An exclude entry on a key left at its default matches through the default (depth 8).
  const auto all = expand({{"defaults", base},
                           {"axes", {{"dt", {1e-3, 2e-3}}}},
                           {"exclude", {{{"octree.depth", 8}, {"dt", 1e-3}}}}});
  ASSERT_EQ(all.cells.size(), 1u);
  EXPECT_EQ(all.cells[0].assignment["dt"], 2e-3);
  // Excluding invalid combinations is allowed: they are never validated.
  const auto valid = expand({{"defaults", base},
                             {"axes", {{"solver.name", {"cholmod", "multigrid"}}}},
                             {"exclude", {{{"solver.name", "multigrid"}, {"basis", "hat"}}}}});
  EXPECT_EQ(valid.cells.size(), 1u);
  // Indices stay dense after exclusion (shards depend on it).
  for (size_t i = 0; i < e.cells.size(); ++i) EXPECT_EQ(e.cells[i].index, int(i));
}

TEST(ExperimentConfig, RepetitionsAreInnermost) {
  const auto e = expand({{"defaults", base}, {"axes", {{"dt", {1e-3, 2e-3}}}}, {"repetitions", 3}});
  ASSERT_EQ(e.cells.size(), 6u);
  for (int i = 0; i < 6; ++i) {
    EXPECT_EQ(e.cells[i].repetition, i % 3);
    EXPECT_EQ(e.cells[i].assignment["dt"], i < 3 ? 1e-3 : 2e-3);
  }
  EXPECT_EQ(expand({{"defaults", base}}).cells.size(), 1u);  // no axes: one cell
}

TEST(ExperimentConfig, QuickOverridesTheFullMatrix) {
  const json j = {{"name", "s"},
                  {"defaults", {{"mesh", "icosphere:level=3"}, {"steps", 100}, {"dt", 1e-3}}},
                  {"axes", {{"dt", {1e-3, 2e-3, 4e-3}}, {"solver.name", {"cholmod", "pcg"}}}},
                  {"repetitions", 3},
                  {"exclude", {{{"solver.name", "pcg"}, {"dt", 4e-3}}}},
                  {"quick",
                   {{"defaults", {{"mesh", "icosphere:level=1"}, {"steps", 3}}},
                    {"axes", {{"dt", {1e-3}}}},
                    {"exclude", json::array()},
                    {"repetitions", 1}}}};
  const auto full = expand(j), quick = expand(j, true);
  EXPECT_EQ(full.cells.size(), (3u * 2 - 1) * 3);
  ASSERT_EQ(quick.cells.size(), 2u);  // dt replaced, solver.name axis kept
  EXPECT_TRUE(quick.quick);
  for (const auto& c : quick.cells) {
    EXPECT_EQ(c.config["mesh"], "icosphere:level=1");
    EXPECT_EQ(c.config["steps"], 3);
    EXPECT_EQ(c.config["dt"], 1e-3);  // full default kept where quick says nothing
  }
  EXPECT_EQ(full.cells[0].config["steps"], 100);
}

// Dotted keys in `defaults` (as axes, zip and exclude name keys, and as the unknown-key message
// lists them) set the nested option; a dotted key wins over the nested object of its name, and
// quick.defaults takes them too. (They were accepted by the check and then refused per cell.)
TEST(ExperimentConfig, DottedKeysInDefaultsSetTheNestedOption) {
  const json j = {{"name", "s"},
                  {"defaults",
                   {{"mesh", "icosphere:level=1"},
                    {"basis", "octree"},
                    {"solver", {{"name", "cholmod"}, {"tolerance", 1e-6}}},
                    {"solver.name", "pcg"},
                    {"octree.depth", 5}}},
                  {"axes", {{"flow", {"mcf"}}}},
                  {"quick", {{"defaults", {{"octree.tracking", "rebuilt"}}}}}};
  for (const bool quick : {false, true}) {
    const auto e = expand(j, quick);
    ASSERT_EQ(e.cells.size(), 1u);
    const json& c = e.cells[0].config;
    EXPECT_EQ(c["solver"]["name"], "pcg");
    EXPECT_EQ(c["solver"]["tolerance"], 1e-6);  // the nested object's other keys kept
    EXPECT_EQ(c["octree"]["depth"], 5);
    EXPECT_EQ(c["octree"]["tracking"], quick ? "rebuilt" : "tracked");
  }
}

TEST(ExperimentConfig, MetricsAreReadStrictly) {
  json defaults = base;
  defaults["steps"] = 100;
  const auto e = expand({{"defaults", defaults},
                         {"axes", {{"solver.name", {"cholmod", "pcg"}}}},
                         {"metrics",
                          {{"quasi_conformal", true},
                           {"sphericity", true},
                           {"every", 10},
                           {"frames", {100, 1, 10}},
                           {"reference", {{"solver.name", "cholmod"}}}}}});
  EXPECT_TRUE(e.metrics.quasi_conformal);
  EXPECT_EQ(e.metrics.every, 10);
  EXPECT_EQ(e.metrics.frames, (std::vector<int>{1, 10, 100}));
  EXPECT_EQ(e.metrics.reference, (json{{"solver.name", "cholmod"}}));
}

void expect_error(const json& j, const std::string& path, bool quick = false) {
  try {
    parse_experiment_config(j, "my_study.json", quick);
    ADD_FAILURE() << "accepted: " << j.dump();
  } catch (const ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("my_study.json"), std::string::npos) << what;
    EXPECT_NE(what.find(path), std::string::npos) << "expected \"" << path << "\" in: " << what;
  }
}

TEST(ExperimentConfig, ErrorsNameTheFileAndTheKeyPath) {
  expect_error({{"defaults", base}, {"axis", {{"dt", {1e-3}}}}}, "axis");  // unknown top-level key
  expect_error({{"defaults", {{"mesh", "x"}, {"solver", {{"cycels", 2}}}}}},
               "defaults.solver.cycels");
  expect_error({{"defaults", {{"mesh", "x"}, {"stepz", 2}}}}, "defaults.stepz");
  expect_error({{"defaults", base},
                {"zip", json::parse(R"([{"solver.name": ["pcg", "cholmod"], "dt": [0.001]}])")}},
               "zip[0].solver.name");
  expect_error({{"defaults", base}, {"axes", {{"solver.cycels", {1, 2}}}}}, "axes.solver.cycels");
  expect_error({{"defaults", base}, {"axes", {{"dt", json::array()}}}}, "axes.dt");
  expect_error({{"defaults", base},
                {"axes", {{"dt", {1e-3}}}},
                {"exclude", json::parse(R"([{"dtt": 0.001}])")}},
               "exclude[0].dtt");
  expect_error({{"defaults", base}, {"repetitions", 0}}, "repetitions");
  expect_error({{"defaults", base}, {"metrics", {{"every", 0}}}}, "metrics.every");
  expect_error({{"defaults", base}, {"metrics", {{"sphericty", true}}}}, "metrics.sphericty");
  expect_error(
      {{"defaults", base}, {"metrics", {{"frames", {1}}, {"reference", {{"solver.name", "pcg"}}}}}},
      "metrics.reference");
  expect_error({{"defaults", base}, {"metrics", {{"frames", {0, 50}}}}},
               "metrics.frames");  // base has 2 steps
  expect_error({{"defaults", base}, {"quick", {{"axis", json::object()}}}}, "quick.axis");
  expect_error({{"defaults", base}, {"quick", {{"defaults", {{"octree", {{"dept", 3}}}}}}}},
               "quick.defaults.octree.dept");
  // Wrong type / out of range in a cell: the flow config's own message with the key path.
  expect_error({{"defaults", base}, {"axes", {{"solver.cycles", {1, 0}}}}}, "solver.cycles");
  expect_error({{"defaults", base}, {"axes", {{"steps", {"two"}}}}}, "steps");
  expect_error({{"defaults", {{"steps", 2}}}}, "mesh");                           // missing mesh
  expect_error({{"defaults", base}, {"axes", {{"dt", {1e-3, 0.001}}}}}, "axes");  // duplicate cells
  // An exclude entry that removes nothing: a typo in a value, or a value no axis has.
  expect_error({{"defaults", base},
                {"axes", {{"basis", {"hat"}}}},
                {"exclude", json::parse(R"([{"basis": "hta"}])")}},
               "exclude[0]");
  expect_error({{"defaults", base},
                {"axes", {{"dt", {1e-3}}}},
                {"exclude", json::parse(R"([{"dt": 0.005}])")}},
               "exclude[0]");
}

// A matrix of more cells than any study could run is refused before it is expanded: a few lines
// of axes, or a million repetitions, would otherwise exhaust the memory while expanding.
TEST(ExperimentConfig, HugeMatricesAreRefusedBeforeExpanding) {
  json values = json::array();
  for (int i = 0; i < 100; ++i) values.push_back(i + 1);
  expect_error({{"defaults", base},
                {"axes", {{"steps", values}, {"solver.cycles", values}}},
                {"repetitions", 11}},
               "the matrix has 100 x 100 x 11 repetitions = 110000 cells");
  expect_error({{"defaults", base}, {"repetitions", 1000000}}, "= 1000000 cells, more than");
  json quick = {{"axes", {{"steps", values}}}, {"repetitions", 1001}};
  expect_error({{"defaults", base}, {"quick", quick}}, "axes (with quick.axes): the matrix", true);
  // Up to the limit the matrix expands.
  EXPECT_EQ(expand({{"defaults", base}, {"axes", {{"steps", values}}}, {"repetitions", 1000}})
                .cells.size(),
            100000u);
}

TEST(ExperimentConfig, ExcludeEntriesMustMatchInTheirOwnVariant) {
  // The full matrix's exclude applied to quick.axes may rightly match nothing; quick.exclude
  // entries must match in the quick run.
  const json j = {{"defaults", base},
                  {"axes", {{"dt", {1e-3, 2e-3}}}},
                  {"exclude", json::parse(R"([{"dt": 0.002}])")},
                  {"quick", {{"axes", {{"dt", {1e-3}}}}}}};
  EXPECT_EQ(expand(j).cells.size(), 1u);
  EXPECT_EQ(expand(j, true).cells.size(), 1u);
  json own = j;
  own["quick"]["exclude"] = json::parse(R"([{"dt": 0.003}])");
  try {
    expand(own, true);
    ADD_FAILURE() << "quick.exclude matching nothing was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("quick.exclude[0]"), std::string::npos) << e.what();
  }
}

TEST(ExperimentConfig, ConfigFilesAreReadStrictly) {
  // Duplicate keys (JSON keeps the last silently), numbers out of double range and a --quick
  // run of a config without a quick section are errors naming the file.
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / "mcfbench_config_files";
  std::filesystem::create_directories(dir);
  auto file = [&](const std::string& name, const std::string& text) {
    std::ofstream((dir / name).string()) << text;
    return (dir / name).string();
  };
  auto error_of = [](const std::function<void()>& f) -> std::string {
    try {
      f();
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "";
  };
  const std::string dup =
      file("dup.json", R"({"defaults": {"mesh": "icosphere:level=1", "dt": 0.001, "dt": 0.01}})");
  std::string what = error_of([&] { load_experiment_config(dup, false); });
  EXPECT_NE(what.find("dup.json: defaults.dt: key appears twice"), std::string::npos) << what;
  what = error_of([&] {
    read_config_file(file("dup2.json", R"({"axes": {"x": [1]}, "zip": [{"dt": [1], "dt": [2]}]})"));
  });
  EXPECT_NE(what.find("dup2.json: zip[].dt: key appears twice"), std::string::npos) << what;
  // The same key in two different objects is fine.
  EXPECT_EQ(
      read_config_file(file(
          "ok.json", R"({"a": {"x": 1}, "b": {"x": 2}, "x": [{"x": 1}, {"x": 2}]})"))["b"]["x"],
      2);
  const std::string big =
      file("big.json", R"({"defaults": {"mesh": "icosphere:level=1", "dt": 1e400}})");
  what = error_of([&] { load_experiment_config(big, false); });
  EXPECT_NE(what.find("big.json: defaults.dt: "), std::string::npos) << what;
  EXPECT_NE(what.find("overflow"), std::string::npos) << what;
  what =
      error_of([&] { read_config_file(file("big2.json", R"({"axes": {"dt": [0.1, -1e999]}})")); });
  EXPECT_NE(what.find("big2.json: axes.dt[]: "), std::string::npos) << what;
  const std::string plain = file("plain.json", R"({"defaults": {"mesh": "icosphere:level=1"}})");
  EXPECT_EQ(load_experiment_config(plain, false).cells.size(), 1u);
  what = error_of([&] { load_experiment_config(plain, true); });
  EXPECT_NE(what.find("plain.json: --quick"), std::string::npos) << what;
  std::filesystem::remove_all(dir);
}

TEST(ExperimentConfig, EveryShippedStudyConfigExpandsInBothVariants) {
  // harness/configs/*.json (not the *.reference.json tables the reports read, nor the list of
  // studies, studies.json): the studies the docs/studies.md documents must load, full and quick,
  // with this build's keys and checks.
  const auto configs = std::filesystem::path(MCFBENCH_SOURCE_DIR) / "harness" / "configs";
  int n = 0;
  for (const auto& entry : std::filesystem::directory_iterator(configs)) {
    const std::string name = entry.path().filename().string();
    if (entry.path().extension() != ".json" || name.find(".reference.") != std::string::npos ||
        name == "studies.json")
      continue;
    ++n;
    for (bool quick : {false, true}) {
      try {
        EXPECT_FALSE(load_experiment_config(entry.path().string(), quick).cells.empty()) << name;
      } catch (const std::exception& e) {
        ADD_FAILURE() << name << (quick ? " --quick" : "") << ": " << e.what();
      }
    }
  }
  EXPECT_GE(n, 7) << "table1, sphere_error, model_error, depth_cycles, cubature, cmcf, time_order";
}

TEST(ExperimentConfig, ShardsPartitionTheCells) {
  const auto e = expand({{"defaults", base},
                         {"axes", {{"dt", {1e-3, 2e-3, 3e-3}}, {"steps", {1, 2, 3}}}},
                         {"repetitions", 2}});
  ASSERT_EQ(e.cells.size(), 18u);
  for (int n = 1; n <= 5; ++n) {
    std::vector<int> owner(e.cells.size(), -1);
    for (int i = 0; i < n; ++i)
      for (const auto& c : e.cells)
        if (in_shard(c.index, i, n)) {
          EXPECT_EQ(owner[c.index], -1)
              << "cell " << c.index << " in shards " << owner[c.index] << " and " << i;
          owner[c.index] = i;
        }
    for (size_t k = 0; k < owner.size(); ++k)
      EXPECT_GE(owner[k], 0) << "cell " << k << " in no shard of " << n;
  }
  int i = -1, n = -1;
  parse_shard("3/16", i, n);
  EXPECT_EQ(i, 3);
  EXPECT_EQ(n, 16);
  EXPECT_THROW(parse_shard("16/16", i, n), std::invalid_argument);
  EXPECT_THROW(parse_shard("1-4", i, n), std::invalid_argument);
  EXPECT_THROW(parse_shard("1/0", i, n), std::invalid_argument);
}

TEST(CellHash, StableAndSensitive) {
  const auto e = expand({{"defaults", base}, {"axes", {{"dt", {1e-3, 2e-3}}}}, {"repetitions", 2}});
  const std::string fp = "0123456789abcdef";
  const std::string k0 = cell_key(e.cells[0].config, 0, fp);
  EXPECT_EQ(k0.size(), 16u);
  EXPECT_EQ(k0, cell_key(e.cells[0].config, 0, fp));  // deterministic
  EXPECT_EQ(k0, cell_key(json::parse(e.cells[0].config.dump()), 0,
                         fp));                        // independent of key order/roundtrip
  EXPECT_NE(k0, cell_key(e.cells[0].config, 1, fp));  // repetition
  EXPECT_NE(k0, cell_key(e.cells[2].config, 0, fp));  // config (dt)
  EXPECT_NE(k0, cell_key(e.cells[0].config, 0, "fedcba9876543210"));  // input mesh
  EXPECT_NE(cell_hash(k0, "abc"), cell_hash(k0, "abd"));              // code version
  EXPECT_EQ(cell_hash(k0, "abc"), cell_hash(k0, "abc"));
  // A default written out explicitly is the same cell as the default left implicit.
  const auto explicit_default = expand(
      {{"defaults", {{"mesh", "icosphere:level=1"}, {"steps", 2}, {"octree", {{"depth", 8}}}}}});
  const auto implicit_default = expand({{"defaults", base}});
  EXPECT_EQ(cell_key(explicit_default.cells[0].config, 0, fp),
            cell_key(implicit_default.cells[0].config, 0, fp));
  // Known FNV-1a test vector.
  EXPECT_EQ(hex16(fnv1a64("a")), "af63dc4c8601ec8c");
  TriangleMesh m;
  m.vertices = Positions::Zero(3, 3);
  m.faces = Triangles(1, 3);
  m.faces << 0, 1, 2;
  const std::string f0 = mesh_fingerprint(m);
  m.vertices(1, 0) = 1e-12;
  EXPECT_NE(f0, mesh_fingerprint(m));
}

}  // namespace
}  // namespace mcf
