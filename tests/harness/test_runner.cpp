// The runner in-process (per-step metrics, frames, reference distances, a failing cell, a stop
// request, an output that cannot be written) and end to end through the binary (resume after a
// deleted file, after SIGKILL, after SIGTERM and SIGINT, shards + collect, collect on a run that
// finished nothing, config errors that write nothing).

#include "config/config_reader.h"
#include "harness/environment.h"
#include "harness/memory_budget.h"
#include "harness/runner.h"

#include "harness_test_util.h"

#include <algorithm>
#include <chrono>
#include <csignal>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <thread>
#include <tuple>
#include <vector>

namespace mcf {
namespace {

using namespace mcf::test;
using nlohmann::json;

TEST(Runner, PerStepMetricsFramesAndReferenceDistance) {
  const fs::path out = fresh_dir("metrics");
  const json j = {{"name", "m"},
                  {"defaults", {{"mesh", "icosphere:level=1"}, {"steps", 4}, {"dt", 1e-3}}},
                  {"axes", {{"dt", {1e-3, 4e-3}}}},
                  {"metrics",
                   {{"quasi_conformal", true},
                    {"sphericity", true},
                    {"every", 2},
                    {"frames", {0, 2, 4}},
                    {"reference", {{"dt", 1e-3}}},
                    {"distance_samples", 500}}}};
  const ExperimentConfig e = parse_experiment_config(j, "m.json", false);
  RunOptions o;
  o.out_dir = out.string();
  const RunSummary s = run_experiment(e, o);
  EXPECT_EQ(s.ran, 2);
  EXPECT_EQ(s.errors, 0);
  EXPECT_EQ(s.distances, 1);
  MeshCache meshes;
  const auto plans = plan_cells(e, out.string(), meshes);
  const json ref = read_json(plans[0].file), other = read_json(plans[1].file);
  for (const json* r : {&ref, &other}) {
    ASSERT_EQ((*r)["status"], "ok");
    ASSERT_EQ((*r)["steps"].size(), 4u);
    EXPECT_FALSE((*r)["steps"][0].contains("metrics"));  // step 1: not a multiple of every=2
    // An icosphere stays nearly a sphere, and its flow nearly conformal.
    EXPECT_GE((*r)["steps"][1]["metrics"]["sphericity"].get<double>(), 0.0);
    EXPECT_LT((*r)["steps"][1]["metrics"]["sphericity"].get<double>(), 0.05);
    EXPECT_GE((*r)["steps"][3]["metrics"]["quasi_conformal"].get<double>(), 1.0 - 1e-12);
    EXPECT_NEAR((*r)["initial_metrics"]["quasi_conformal"].get<double>(), 1.0, 1e-12);
    EXPECT_EQ((*r)["frames"]["steps"], (json{0, 2, 4}));
    for (int step : {0, 2, 4}) {
      char name[32];
      std::snprintf(name, sizeof name, "frame_%05d.ply", step);
      EXPECT_TRUE(fs::exists(out / (*r)["frames"]["dir"].get<std::string>() / name));
    }
    EXPECT_EQ((*r)["cell"]["study"], "m");
    EXPECT_EQ((*r)["study_config"], j);
    EXPECT_TRUE((*r).contains("environment"));
    EXPECT_GT((*r)["peak_memory_bytes"].get<long long>(), 0);
    // The hypervisor's stolen CPU time while the cell ran (Linux reports it; never negative).
    if (cpu_steal_seconds() >= 0) {
      EXPECT_GE((*r)["steal_seconds"].get<double>(), 0.0);
    }
  }
  EXPECT_FALSE(ref.contains("reference_distance"));  // the reference itself
  ASSERT_TRUE(other.contains("reference_distance"));
  const json& d = other["reference_distance"];
  ASSERT_EQ(d.size(), 3u);
  EXPECT_EQ(d[0]["step"], 0);
  EXPECT_NEAR(d[0]["rms"].get<double>(), 0.0, 1e-6);  // same input mesh (frames are float PLY)
  EXPECT_GT(d[2]["rms"].get<double>(), 1e-4);         // 4x the time step: visibly further along
  EXPECT_EQ(d[2]["samples"], 500);
  EXPECT_EQ(other["reference_cell"]["hash"], plans[0].hash);
}

TEST(Runner, EachCellLoadsItsMeshAsItsBasisAndRepairSettingAsk) {
  // A tent whose bottom edge carries a zero-area cap: the octree cell keeps it, the hat cell with
  // repair_degenerate removes it, and one mesh cache serves both (the treatment is part of its
  // key).
  const fs::path out = fresh_dir("degenerate_cells");
  const fs::path tent = out / "tent.off";
  write_text(tent,
             "OFF\n6 6 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 0 0\n0.5 0.5 0.5\n"
             "3 0 4 5\n3 4 1 5\n3 1 2 5\n3 2 3 5\n3 3 0 5\n3 0 1 4\n");
  const json j = {{"name", "d"},
                  {"defaults", {{"mesh", tent.string()}, {"steps", 1}, {"octree.depth", 4}}},
                  {"zip", {{{"basis", {"octree", "hat"}}, {"repair_degenerate", {false, true}}}}}};
  const ExperimentConfig e = parse_experiment_config(j, "d.json", false);
  RunOptions o;
  o.out_dir = (out / "results").string();
  const RunSummary s = run_experiment(e, o);
  EXPECT_EQ(s.errors, 0);
  MeshCache meshes;
  const auto plans = plan_cells(e, o.out_dir, meshes);
  ASSERT_EQ(plans.size(), 2u);
  const json octree = read_json(plans[0].file), hat = read_json(plans[1].file);
  EXPECT_EQ(octree["status"], "ok");
  EXPECT_EQ(octree["mesh"]["degenerate_faces"], 1);
  EXPECT_EQ(hat["status"], "ok");
  EXPECT_EQ(hat["mesh"]["repaired_faces"], 1);
  EXPECT_EQ(hat["mesh"]["faces"], 4);
  // Without the repair, the hat cell stops the plan before anything runs, naming the option.
  json bare = j;
  bare.erase("zip");
  bare["defaults"]["basis"] = "hat";
  try {
    MeshCache fresh;
    plan_cells(parse_experiment_config(bare, "bare.json", false), "", fresh);
    FAIL() << "a hat cell planned on a mesh with a zero-area face";
  } catch (const std::exception& ex) {
    EXPECT_NE(std::string(ex.what()).find("--repair-degenerate"), std::string::npos) << ex.what();
  }
}

TEST(Runner, AFlowThatStopsEarlyHasMetricsAtItsLastCompletedStep) {
  // Explicit Euler beyond its stability limit: the area grows by more than 5% at step 6 and the
  // flow stops there, so step 5 is its last state. With every=4 step 5 is neither a multiple of
  // 4 nor config.steps; it gets metrics all the same, those of its positions (the every=1 run
  // measures each step as the flow makes it), and the stopping step gets none.
  auto run_every = [](int every) {
    const fs::path out = fresh_dir("stopped_every_" + std::to_string(every));
    const json j = {
        {"defaults",
         {{"mesh", "icosphere:level=1"},
          {"integrator", "explicit-euler"},
          {"dt", 0.05},
          {"steps", 50}}},
        {"metrics", {{"quasi_conformal", true}, {"sphericity", true}, {"every", every}}}};
    const ExperimentConfig e = parse_experiment_config(j, "stop.json", false);
    RunOptions o;
    o.out_dir = out.string();
    EXPECT_EQ(run_experiment(e, o).ran, 1);
    MeshCache meshes;
    return read_json(plan_cells(e, out.string(), meshes)[0].file);
  };
  const json r = run_every(4), all = run_every(1);
  ASSERT_EQ(r["status"], "singular") << r["stop"].dump();
  ASSERT_EQ(r["stop"]["step"], 6) << r["stop"].dump();
  ASSERT_EQ(r["steps"].size(), 6u);
  for (int i : {0, 1, 2, 5})
    EXPECT_FALSE(r["steps"][size_t(i)].contains("metrics")) << "step " << i + 1;
  ASSERT_TRUE(r["steps"][3].contains("metrics"));  // step 4: a multiple of every=4
  ASSERT_TRUE(r["steps"][4].contains("metrics"));  // step 5: the last completed step
  EXPECT_EQ(r["steps"][3]["metrics"], all["steps"][3]["metrics"]);
  EXPECT_EQ(r["steps"][4]["metrics"], all["steps"][4]["metrics"]);
  EXPECT_NE(r["steps"][4]["metrics"]["quasi_conformal"].get<double>(),
            r["steps"][3]["metrics"]["quasi_conformal"].get<double>());  // not step 4's state again
  EXPECT_FALSE(all["steps"][5].contains("metrics"));  // the stopping step's positions are dropped
}

/// Three cells (dt 1e-3, 2e-3, 4e-3) of a two-step flow whose frame 2 is compared with the dt =
/// 1e-3 cell's: what the sharded-distance tests run.
ExperimentConfig three_dts_with_reference() {
  const json j = {
      {"defaults", {{"mesh", "icosphere:level=1"}, {"steps", 2}}},
      {"axes", {{"dt", {1e-3, 2e-3, 4e-3}}}},
      {"metrics", {{"frames", {2}}, {"reference", {{"dt", 1e-3}}}, {"distance_samples", 100}}}};
  return parse_experiment_config(j, "r.json", false);
}

// A reference is a flow of the same surface: where the study excludes its reference on a mesh,
// that mesh's cells get no distances (not distances to another mesh's reference), and distances
// an earlier run recorded there are dropped.
TEST(Runner, ReferenceDistancesOnlyToAReferenceOfTheSameMesh) {
  const fs::path out = fresh_dir("reference_same_mesh");
  const json j = {
      {"name", "r"},
      {"defaults", {{"steps", 2}, {"dt", 1e-3}}},
      {"axes", {{"mesh", {"icosphere:level=1", "icosphere:level=2"}}, {"dt", {1e-3, 4e-3}}}},
      {"exclude", {{{"mesh", "icosphere:level=2"}, {"dt", 1e-3}}}},
      {"metrics", {{"frames", {2}}, {"reference", {{"dt", 1e-3}}}, {"distance_samples", 200}}}};
  const ExperimentConfig e = parse_experiment_config(j, "r.json", false);
  RunOptions o;
  o.out_dir = out.string();
  std::vector<std::pair<int, int>> progress;  // (done, total) as the distances are added
  o.on_distance = [&](int done, int total, int) { progress.emplace_back(done, total); };
  const RunSummary s = run_experiment(e, o);
  ASSERT_EQ(s.ran, 3);
  EXPECT_EQ(s.distances, 1);
  EXPECT_EQ(progress, (std::vector<std::pair<int, int>>{{1, 1}}));
  MeshCache meshes;
  const auto plans = plan_cells(e, out.string(), meshes);
  const CellPlan* lone = nullptr;  // icosphere:level=2 at dt 4e-3: no reference on its mesh
  for (const CellPlan& p : plans) {
    const json r = read_json(p.file);
    const bool on_level1 = p.cell.flow.mesh == "icosphere:level=1";
    const bool is_reference = p.cell.flow.dt == 1e-3;
    EXPECT_EQ(r.contains("reference_distance"), on_level1 && !is_reference) << p.cell.flow.mesh;
    if (!on_level1) lone = &p;
  }
  ASSERT_NE(lone, nullptr);
  // Distances recorded by a run that matched another mesh's reference are dropped on a rerun.
  json planted = read_json(lone->file);
  planted["reference_distance"] = json::array();
  planted["reference_cell"] = json::object();
  std::ofstream(lone->file) << planted.dump(1) << "\n";
  RunOptions again = o;
  again.distances_only = true;
  run_experiment(e, again);
  EXPECT_FALSE(read_json(lone->file).contains("reference_distance"));
  EXPECT_FALSE(read_json(lone->file).contains("reference_cell"));
}

TEST(Runner, ShardedReferenceDistancesAreFilledInByALaterRun) {
  const fs::path out = fresh_dir("sharded_ref");
  const ExperimentConfig e = three_dts_with_reference();
  RunOptions o;
  o.out_dir = out.string();
  o.shard_count = 2;
  o.shard_index = 1;  // cell 1 only: its reference (cell 0) is not there yet
  EXPECT_EQ(run_experiment(e, o).distances, 0);
  o.shard_index = 0;  // cells 0 and 2: cell 2 gets its distance, cell 1 belongs to shard 1
  EXPECT_EQ(run_experiment(e, o).distances, 1);
  o.shard_count = 1;  // unsharded rerun: nothing runs, the missing distance is added
  const RunSummary s = run_experiment(e, o);
  EXPECT_EQ(s.ran, 0);
  EXPECT_EQ(s.distances, 1);
  MeshCache meshes;
  const auto plans = plan_cells(e, out.string(), meshes);
  for (int i : {1, 2})
    EXPECT_EQ(read_json(plans[size_t(i)].file)["reference_distance"].size(), 1u) << i;
  EXPECT_EQ(run_experiment(e, o).distances, 0);  // nothing stale any more
}

TEST(Runner, DistancesOnlyRunsNoCellAndWritesNoPlan) {
  // After an array that lost a task: shard 0 finished (cells 0 and 2), shard 1's cell 1 is
  // missing. A distances-only pass adds cell 2's distance to cell 0 and leaves cell 1 missing.
  const fs::path out = fresh_dir("distances_only");
  const ExperimentConfig e = three_dts_with_reference();
  RunOptions o;
  o.out_dir = out.string();
  o.shard_count = 2;
  o.shard_index = 0;
  ASSERT_EQ(run_experiment(e, o).ran, 2);
  MeshCache meshes;
  const auto plans = plan_cells(e, out.string(), meshes);
  // As if cell 2 had finished before its reference cell: its distance is not there yet.
  json cell2 = read_json(plans[2].file);
  cell2.erase("reference_distance");
  cell2.erase("reference_cell");
  write_text(plans[2].file, cell2.dump());
  const auto plans_before = fs::directory_iterator(out / kPlanFolder);
  const size_t plan_files = size_t(std::distance(plans_before, fs::directory_iterator{}));

  RunOptions d;
  d.out_dir = out.string();
  d.distances_only = true;
  const RunSummary s = run_experiment(e, d);
  EXPECT_EQ(s.ran, 0);
  EXPECT_EQ(s.skipped, 2);
  EXPECT_EQ(s.not_run, 1);
  EXPECT_EQ(s.distances, 1);
  EXPECT_FALSE(fs::exists(plans[1].file)) << "a distances-only pass ran a cell";
  EXPECT_EQ(read_json(plans[2].file)["reference_distance"].size(), 1u);
  EXPECT_EQ(
      size_t(std::distance(fs::directory_iterator(out / kPlanFolder), fs::directory_iterator{})),
      plan_files)
      << "a distances-only pass wrote a plan";
  EXPECT_EQ(run_experiment(e, d).distances, 0);  // nothing left to add
  // Into a folder that does not exist: nothing to add, nothing created.
  d.out_dir = (out / "none").string();
  EXPECT_EQ(run_experiment(e, d).not_run, 3);
  EXPECT_FALSE(fs::exists(out / "none"));
}

TEST(Runner, ACellErrorIsRecordedAndTheRunGoesOn) {
  // The unit cube does not hold a radius-1 sphere: that cell's flow throws while it sets up.
  const fs::path out = fresh_dir("error");
  const json j = {{"defaults",
                   {{"mesh", "icosphere:level=1"},
                    {"steps", 2},
                    {"basis", "octree"},
                    {"octree", {{"depth", 4}}}}},
                  {"axes", {{"octree.cube", {"tight", "unit"}}}},
                  {"metrics", {{"sphericity", true}}}};
  const ExperimentConfig e = parse_experiment_config(j, "e.json", false);
  RunOptions o;
  o.out_dir = out.string();
  const RunSummary s = run_experiment(e, o);
  EXPECT_EQ(s.ran, 2);
  EXPECT_EQ(s.errors, 1);
  MeshCache meshes;
  const auto plans = plan_cells(e, out.string(), meshes);
  const json bad = read_json(plans[1].file), good = read_json(plans[0].file);
  ASSERT_EQ(plans[1].cell.assignment["octree.cube"], "unit");
  EXPECT_EQ(bad["status"], "error");
  EXPECT_NE(bad["error"].get<std::string>().find("cube"), std::string::npos) << bad["error"];
  EXPECT_EQ(bad["cell"]["index"], 1);
  EXPECT_EQ(good["status"], "ok");
}

TEST(Runner, OnStepReportsEveryStepOfTheCellsThatRunAndNoneOfTheSkippedOnes) {
  const fs::path out = fresh_dir("on_step");
  const json j = {{"defaults", {{"mesh", "icosphere:level=1"}, {"steps", 3}}},
                  {"axes", {{"dt", {1e-3, 2e-3}}}}};
  const ExperimentConfig e = parse_experiment_config(j, "s.json", false);
  RunOptions o;
  o.out_dir = out.string();
  std::vector<std::tuple<int, int, int, int, int>>
      seen;  // cell number, total, cell index, step, steps
  o.on_step = [&](const StepReport& r) {
    seen.emplace_back(r.cell_number, r.total, r.plan->cell.index, r.step, r.steps);
  };
  ASSERT_EQ(run_experiment(e, o).ran, 2);
  std::vector<std::tuple<int, int, int, int, int>> expected;
  for (int cell = 0; cell < 2; ++cell)
    for (int step = 0; step <= 3; ++step) expected.emplace_back(cell + 1, 2, cell, step, 3);
  EXPECT_EQ(seen, expected);
  // Rerun with the second cell's file gone: only it runs, as cell 2 of 2.
  MeshCache meshes;
  fs::remove(plan_cells(e, out.string(), meshes)[1].file);
  seen.clear();
  ASSERT_EQ(run_experiment(e, o).ran, 1);
  expected.clear();
  for (int step = 0; step <= 3; ++step) expected.emplace_back(2, 2, 1, step, 3);
  EXPECT_EQ(seen, expected);
}

TEST(Runner, AStopRequestDropsTheRunningCellAndKeepsThePlanAndTheFinishedCells) {
  const fs::path out = fresh_dir("stop");
  const json j = {{"name", "stop"},
                  {"defaults", {{"mesh", "icosphere:level=1"}, {"steps", 4}, {"save_every", 2}}},
                  {"axes", {{"dt", {1e-3, 2e-3, 3e-3}}}}};
  const ExperimentConfig e = parse_experiment_config(j, "stop.json", false);
  MeshCache meshes;
  const auto plans = plan_cells(e, out.string(), meshes);
  RunOptions o;
  o.out_dir = out.string();
  // Stop once the second cell has written its frame of step 2: between two of its steps.
  int signal = 0;
  o.on_step = [&](const StepReport& r) {
    if (r.plan->cell.index == 1 && r.step == 2) signal = SIGTERM;
  };
  o.stop_requested = [&] { return signal; };
  try {
    run_experiment(e, o);
    FAIL() << "the run did not stop";
  } catch (const RunStopped& stop) {
    EXPECT_EQ(stop.signal, SIGTERM);
    EXPECT_EQ(stop.done, 1);
    EXPECT_EQ(stop.summary.ran, 1);
  }
  EXPECT_TRUE(fs::exists(run_plan_path(out.string(), e, 0, 1)));
  EXPECT_EQ(read_json(plans[0].file)["status"], "ok");
  EXPECT_TRUE(fs::exists(out / "frames" / plans[0].hash / "frame_00004.ply"));
  EXPECT_FALSE(fs::exists(plans[1].file)) << "the stopped cell has a result";
  EXPECT_FALSE(fs::exists(out / "frames" / plans[1].hash)) << "the stopped cell's frames are left";
  EXPECT_FALSE(fs::exists(plans[2].file));

  // A stop before any cell ran on this pass leaves the results as they are.
  signal = SIGINT;
  EXPECT_THROW(run_experiment(e, o), RunStopped);
  EXPECT_EQ(result_files(out).size(), 1u);

  signal = 0;
  o.on_step = nullptr;
  const RunSummary s = run_experiment(e, o);
  EXPECT_EQ(s.ran, 2);
  EXPECT_EQ(s.skipped, 1);
  for (const auto& p : plans) EXPECT_EQ(read_json(p.file)["status"], "ok") << p.file;
}

TEST(Runner, AFileThatCannotBeWrittenStopsTheRunInsteadOfFailingTheCell) {
  // A file where the frames folder goes: the first cell cannot write its frames. That is the
  // output's fault, not the cell's, and would fail every cell after it: the run stops and names
  // the path; no result is written for the cell, so a rerun once the path is fixed runs it.
  const fs::path out = fresh_dir("unwritable");
  write_text(out / "frames", "not a folder");
  const json j = {{"name", "unwritable"},
                  {"defaults", {{"mesh", "icosphere:level=1"}, {"steps", 2}, {"save_every", 1}}},
                  {"axes", {{"dt", {1e-3, 2e-3}}}}};
  const ExperimentConfig e = parse_experiment_config(j, "unwritable.json", false);
  RunOptions o;
  o.out_dir = out.string();
  try {
    run_experiment(e, o);
    FAIL() << "the run went on";
  } catch (const RunStopped&) {
    FAIL() << "not a stop request";
  } catch (const std::runtime_error& ex) {
    const std::string what = ex.what();
    EXPECT_NE(what.find((out / "frames").string()), std::string::npos) << what;
    EXPECT_NE(what.find("Rerun the same command to resume"), std::string::npos) << what;
  }
  EXPECT_TRUE(result_files(out).empty());
  EXPECT_TRUE(fs::exists(run_plan_path(out.string(), e, 0, 1)));
  fs::remove(out / "frames");
  EXPECT_EQ(run_experiment(e, o).ran, 2);
}

TEST(Runner, ACellTooLargeForTheMemoryStopsTheRunBeforeAnythingIsWritten) {
  // Shard 1's cell is refused from its spec's sizes (its sphere is never generated), shard 0's
  // under a smaller budget from its mesh's sizes once loaded; each shard checks only its cells.
  const fs::path out = fresh_dir("memory") / "results";
  const json j = {{"name", "memory"},
                  {"defaults",
                   {{"steps", 1},
                    {"basis", "octree"},
                    {"octree", {{"depth", 7}}},
                    {"solver", {{"name", "multigrid"}}}}},
                  {"axes", {{"mesh", {"icosphere:level=3", "sphere:vertices=20000000"}}}}};
  const ExperimentConfig e = parse_experiment_config(j, "memory.json", false);
  for (const auto& [shard, budget] : {std::pair<int, const char*>{1, "1G"}, {0, "64M"}}) {
    RunOptions o;
    o.out_dir = out.string();
    o.max_memory = budget;
    o.shard_index = shard;
    o.shard_count = 2;
    try {
      run_experiment(e, o);
      FAIL() << "shard " << shard << " ran";
    } catch (const MemoryLimitError& ex) {
      const std::string what = ex.what();
      for (const std::string& part :
           {"memory.json (cell " + std::to_string(shard), std::string("estimated"),
            "--max-memory " + std::string(budget)})
        EXPECT_NE(what.find(part), std::string::npos) << part << " in: " << what;
    }
    EXPECT_FALSE(fs::exists(out));
  }
  RunOptions o;
  o.out_dir = out.string();
  o.max_memory = "1G";
  o.shard_count = 2;
  EXPECT_EQ(run_experiment(e, o).ran, 1);
  ASSERT_EQ(result_files(out).size(), 1u);
  const json r = read_json(result_files(out)[0]);
  EXPECT_GT(r["memory_estimate"]["bytes"].get<double>(),
            r["memory_estimate"]["resident_bytes"].get<double>());
}

const char* tiny_config = R"({
  "name": "tiny",
  "defaults": {"mesh": "icosphere:level=1", "steps": 2, "basis": "hat", "solver": {"name": "cholmod"}},
  "axes": {"dt": [0.001, 0.002, 0.003]}
})";

std::map<std::string, fs::file_time_type> age_files(const fs::path& dir) {
  // Back-date the results so a rewrite shows as a newer mtime whatever the clock resolution.
  std::map<std::string, fs::file_time_type> times;
  const auto old = fs::file_time_type::clock::now() - std::chrono::hours(1);
  for (const auto& f : result_files(dir)) {
    fs::last_write_time(f, old);
    times[f.filename().string()] = fs::last_write_time(f);
  }
  return times;
}

TEST(RunnerCli, RerunRetriesErroredAndUnreadableCellsAndCollectCountsErrors) {
  // An errored cell is not a result: a rerun runs it again (and exits 1 while it still fails),
  // `collect` reports it; a cell file that does not parse is replaced, not "skipped".
  const fs::path dir = fresh_dir("retry");
  write_text(
      dir / "e.json",
      R"({"name": "e", "defaults": {"mesh": "icosphere:level=1", "steps": 1, "basis": "octree",
    "octree": {"depth": 4}, "solver": {"name": "cholmod"}}, "axes": {"octree.cube": ["tight", "unit"]}})");
  Command c = mcfbench("run e.json --out out", dir);
  EXPECT_EQ(c.status, 1) << c.out << c.err;  // the unit cube does not hold a radius-1 sphere
  EXPECT_NE(c.out.find("2 ran, 0 skipped, 1 errors"), std::string::npos) << c.out;
  c = mcfbench("collect out", dir);
  EXPECT_EQ(c.status, 1) << c.out << c.err;
  EXPECT_NE(c.out.find("0 missing, 0 duplicated, 1 errored"), std::string::npos) << c.out;
  EXPECT_NE(c.out.find("errored cell indices: [1]"), std::string::npos) << c.out;
  EXPECT_EQ(read_json(dir / "out" / "index.json")["studies"][0]["errors"], json::array({1}));
  c = mcfbench("run e.json --out out", dir);
  EXPECT_EQ(c.status, 1) << c.out << c.err;
  EXPECT_NE(c.out.find("1 ran (1 retried after an error), 1 skipped, 1 errors"), std::string::npos)
      << c.out;
  // Truncate the good cell's file: the next run recomputes it.
  fs::path good;
  for (const auto& f : result_files(dir / "out"))
    if (read_json(f)["status"] == "ok") good = f;
  ASSERT_FALSE(good.empty());
  write_text(good, "{\"status\": \"ok\", \"tru");
  c = mcfbench("collect out", dir);  // listed, not a crash
  EXPECT_EQ(c.status, 1) << c.out << c.err;
  EXPECT_NE(c.out.find(good.filename().string() + ": unreadable"), std::string::npos) << c.out;
  EXPECT_EQ(read_json(dir / "out" / "index.json")["unreadable"].size(), 1u);
  c = mcfbench("run e.json --out out", dir);
  EXPECT_NE(c.out.find("2 ran (2 retried after an error), 0 skipped, 1 errors"), std::string::npos)
      << c.out;
  EXPECT_EQ(read_json(good)["status"], "ok");
}

TEST(RunnerCli, LogsShowStepProgressEveryProgressSecondsAndABadValueWritesNothing) {
  // stderr is a file here, as under nohup or Slurm: plain lines, at most every
  // MCFBENCH_PROGRESS_SECONDS (0: every step but a cell's last, which its own line reports).
  const fs::path dir = fresh_dir("progress");
  write_text(dir / "tiny.json", tiny_config);
  ::setenv("MCFBENCH_PROGRESS_SECONDS", "0", 1);
  Command c = mcfbench("run tiny.json --out out", dir);
  ASSERT_EQ(c.status, 0) << c.err;
  for (const char* line :
       {"[1/3] cell 0 step 0/2  ", "[1/3] cell 0 step 1/2  ", "[3/3] cell 2 step 1/2  "})
    EXPECT_NE(c.err.find(line), std::string::npos) << line << " in " << c.err;
  EXPECT_EQ(c.err.find("step 2/2"), std::string::npos) << c.err;
  EXPECT_EQ(c.err.find('\r'), std::string::npos) << "a terminal's line in a log";
  EXPECT_LT(c.err.find("[1/3] cell 0 step 1/2"), c.err.find(" ok "))
      << c.err;  // before the cell's own line
  c = mcfbench("flow --mesh icosphere:level=1 --steps 3 --out flow", dir);
  ASSERT_EQ(c.status, 0) << c.err;
  EXPECT_NE(c.err.find("step 2/3  "), std::string::npos) << c.err;
  // The default (60 s) prints nothing for runs this short.
  ::unsetenv("MCFBENCH_PROGRESS_SECONDS");
  c = mcfbench("run tiny.json --out again", dir);
  ASSERT_EQ(c.status, 0) << c.err;
  EXPECT_EQ(c.err.find(" step "), std::string::npos) << c.err;
  ::setenv("MCFBENCH_PROGRESS_SECONDS", "often", 1);
  for (const char* args :
       {"run tiny.json --out bad", "flow --mesh icosphere:level=1 --steps 3 --out bad"}) {
    c = mcfbench(args, dir);
    EXPECT_NE(c.status, 0) << args;
    EXPECT_NE(c.err.find("MCFBENCH_PROGRESS_SECONDS"), std::string::npos) << args << ": " << c.err;
    EXPECT_FALSE(fs::exists(dir / "bad")) << args;
  }
  ::unsetenv("MCFBENCH_PROGRESS_SECONDS");
}

TEST(RunnerCli, RerunRedoesExactlyTheMissingCell) {
  const fs::path dir = fresh_dir("resume");
  write_text(dir / "tiny.json", tiny_config);
  Command c = mcfbench("run tiny.json --out out", dir);
  ASSERT_EQ(c.status, 0) << c.err;
  EXPECT_NE(c.out.find("3 ran, 0 skipped, 0 errors"), std::string::npos) << c.out;
  auto files = result_files(dir / "out");
  ASSERT_EQ(files.size(), 3u);
  // `expand` names the same files.
  const Command x = mcfbench("expand tiny.json", dir);
  ASSERT_EQ(x.status, 0) << x.err;
  for (const auto& f : files) EXPECT_NE(x.out.find(f.stem().string()), std::string::npos) << x.out;

  auto before = age_files(dir / "out");
  const std::string victim = files[1].filename().string();
  fs::remove(files[1]);
  // A temporary file left by a killed writer must not count as a result.
  write_text(dir / "out" / (files[0].filename().string() + ".tmp.12345"), "{\"trunc");
  c = mcfbench("run tiny.json --out out", dir);
  ASSERT_EQ(c.status, 0) << c.err;
  EXPECT_NE(c.out.find("1 ran, 2 skipped"), std::string::npos) << c.out;
  files = result_files(dir / "out");
  ASSERT_EQ(files.size(), 3u);
  for (const auto& f : files) {
    const std::string name = f.filename().string();
    if (name == victim)
      EXPECT_GT(fs::last_write_time(f), before.begin()->second) << "not recomputed";
    else
      EXPECT_EQ(fs::last_write_time(f), before[name]) << name << " recomputed";
  }
  c = mcfbench("run tiny.json --out out --force", dir);
  EXPECT_NE(c.out.find("3 ran, 0 skipped"), std::string::npos) << c.out;
  // Default output folder: results/<name>, and results/<name>-quick with --quick.
  c = mcfbench("run tiny.json --shard 0/3", dir);
  ASSERT_EQ(c.status, 0) << c.err;
  EXPECT_EQ(result_files(dir / "results" / "tiny").size(), 1u);
}

/// `mcfbench run CONFIG --out OUT` started in `dir` in the background, its output discarded (the
/// tests kill it part-way); the child's pid, or -1 when fork failed.
pid_t start_run(const fs::path& dir, const char* config, const char* out) {
  const pid_t pid = fork();
  if (pid == 0) {
    if (::chdir(dir.c_str()) != 0) _exit(127);
    std::freopen("/dev/null", "w", stderr);
    std::freopen("/dev/null", "w", stdout);
    execl(MCFBENCH_BINARY, MCFBENCH_BINARY, "run", config, "--out", out,
          static_cast<char*>(nullptr));
    _exit(127);
  }
  return pid;
}

TEST(RunnerCli, KilledRunLosesNoFinishedCellAndRepeatsNone) {
  const fs::path dir = fresh_dir("killed");
  write_text(dir / "slow.json", R"({
    "name": "slow",
    "defaults": {"mesh": "icosphere:level=4", "steps": 40, "dt": 1e-4, "threads": 1},
    "axes": {"dt": [1e-4, 2e-4, 3e-4, 4e-4, 5e-4, 6e-4]}})");
  const pid_t pid = start_run(dir, "slow.json", "out");
  ASSERT_GT(pid, 0);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (result_files(dir / "out").size() < 2 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ::kill(pid, SIGKILL);
  int status = 0;
  ::waitpid(pid, &status, 0);
  const auto finished = result_files(dir / "out");
  ASSERT_GE(finished.size(), 2u);
  if (finished.size() == 6u) GTEST_SKIP() << "the run finished before it could be killed";
  for (const auto& f : finished) EXPECT_NO_THROW(read_json(f)) << f << " is partial";
  auto before = age_files(dir / "out");

  const Command c = mcfbench("run slow.json --out out", dir);
  ASSERT_EQ(c.status, 0) << c.err;
  const size_t redo = 6 - finished.size();
  EXPECT_NE(
      c.out.find(std::to_string(redo) + " ran, " + std::to_string(finished.size()) + " skipped"),
      std::string::npos)
      << c.out;
  EXPECT_EQ(result_files(dir / "out").size(), 6u);
  for (const auto& [name, t] : before)
    EXPECT_EQ(fs::last_write_time(dir / "out" / name), t) << name << " recomputed";
}

/// As start_run, with the run's stderr in `err`.
pid_t start_logged_run(const fs::path& dir, const char* config, const char* out,
                       const fs::path& err) {
  const pid_t pid = fork();
  if (pid == 0) {
    if (::chdir(dir.c_str()) != 0) _exit(127);
    std::freopen(err.c_str(), "w", stderr);
    std::freopen("/dev/null", "w", stdout);
    execl(MCFBENCH_BINARY, MCFBENCH_BINARY, "run", config, "--out", out,
          static_cast<char*>(nullptr));
    _exit(127);
  }
  return pid;
}

/// Waits (a minute at most) until `dir` holds at least `n` result files.
void wait_for_results(const fs::path& dir, size_t n) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (result_files(dir).size() < n && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
}

TEST(RunnerCli, SigtermAndSigintStopARunThatThenResumesWhereItStopped) {
  // What Slurm sends at a time limit (SIGTERM) and Ctrl-C (SIGINT): the run stops after the step
  // that is running, drops that cell, keeps its plan and the finished cells, says how to resume and
  // exits with 128 + the signal; running the same command again completes the matrix.
  const fs::path dir = fresh_dir("signalled");
  write_text(dir / "slow.json", R"({
    "name": "slow",
    "defaults": {"mesh": "icosphere:level=4", "steps": 40, "dt": 1e-4, "threads": 1},
    "axes": {"dt": [1e-4, 2e-4, 3e-4, 4e-4, 5e-4]}})");
  const fs::path out = dir / "out";
  size_t finished = 0;
  std::map<std::string, fs::file_time_type> before;
  for (const int signal : {SIGTERM, SIGINT}) {
    const std::string name = signal == SIGTERM ? "SIGTERM" : "SIGINT";
    const fs::path err = dir / ("stderr_" + name + ".txt");
    const pid_t pid = start_logged_run(dir, "slow.json", "out", err);
    ASSERT_GT(pid, 0);
    wait_for_results(out, finished + 1);  // one cell more than before: this run is under way
    ::kill(pid, signal);
    int status = 0;
    ::waitpid(pid, &status, 0);
    if (WIFEXITED(status) && WEXITSTATUS(status) == 0 && result_files(out).size() == 5u)
      GTEST_SKIP() << "the run finished before it could be stopped";
    ASSERT_TRUE(WIFEXITED(status)) << name << " ended the run without its handler";
    EXPECT_EQ(WEXITSTATUS(status), 128 + signal) << name;
    const std::string message = slurp(err);
    EXPECT_NE(message.find("stopped by " + name), std::string::npos) << message;
    EXPECT_NE(message.find("Rerun the same command to resume"), std::string::npos) << message;
    EXPECT_NE(message.find("plans/slow@"), std::string::npos) << message;

    const auto files = result_files(out);
    EXPECT_GT(files.size(), finished) << name;
    ASSERT_LT(files.size(), 5u) << name << ": every cell finished";
    for (const auto& f : files) EXPECT_EQ(read_json(f)["status"], "ok") << f;
    for (const auto& [file, t] : before)
      EXPECT_EQ(fs::last_write_time(out / file), t) << file << " was rewritten";
    size_t plans = 0, temporaries = 0;
    for (const auto& entry : fs::recursive_directory_iterator(out)) {
      const std::string file = entry.path().filename().string();
      plans +=
          entry.path().parent_path().filename() == "plans" && entry.path().extension() == ".json";
      temporaries += file.find(".tmp.") != std::string::npos;
    }
    EXPECT_EQ(plans, 1u);
    EXPECT_EQ(temporaries, 0u);
    finished = files.size();
    before = age_files(out);
  }

  const Command c = mcfbench("run slow.json --out out", dir);
  ASSERT_EQ(c.status, 0) << c.err;
  EXPECT_NE(
      c.out.find(std::to_string(5 - finished) + " ran, " + std::to_string(finished) + " skipped"),
      std::string::npos)
      << c.out;
  for (const auto& [file, t] : before)
    EXPECT_EQ(fs::last_write_time(out / file), t) << file << " was recomputed";
  const Command collected = mcfbench("collect out", dir);
  EXPECT_EQ(collected.status, 0) << collected.out << collected.err;
  EXPECT_NE(collected.out.find("5 cells found of 5, 0 missing"), std::string::npos)
      << collected.out;
}

TEST(RunnerCli, CollectFailsOnARunThatFinishedNothingAndOnAFolderWithNothingToCollect) {
  // `collect` used to find problems only among the result files it found: with none (a run killed
  // before its first cell, an empty or mistyped shard folder) it wrote an index and exited 0.
  const fs::path dir = fresh_dir("collect_nothing");
  write_text(dir / "tiny.json", tiny_config);
  ASSERT_EQ(mcfbench("run tiny.json --out out", dir).status, 0);
  Command c = mcfbench("collect out", dir);
  EXPECT_EQ(c.status, 0) << c.out << c.err;
  EXPECT_NE(c.out.find("3 cells found of 3, 0 missing"), std::string::npos) << c.out;
  // No result left, as after a kill before the first cell finished: every planned cell is owed.
  for (const auto& f : result_files(dir / "out")) fs::remove(f);
  c = mcfbench("collect out", dir);
  EXPECT_EQ(c.status, 1) << c.out << c.err;
  EXPECT_NE(c.out.find("0 cells found of 3, 3 missing"), std::string::npos) << c.out;
  EXPECT_NE(c.out.find("missing cells (3): #0 {\"dt\":0.001} ("), std::string::npos) << c.out;
  EXPECT_EQ(read_json(dir / "out" / "index.json")["studies"][0]["missing"], json::array({0, 1, 2}));
  // A folder with neither results nor a plan, alone or beside a complete one.
  fs::create_directories(dir / "empty");
  c = mcfbench("collect empty", dir);
  EXPECT_EQ(c.status, 1) << c.out << c.err;
  EXPECT_NE(c.out.find("empty: no cell results and no run plan"), std::string::npos) << c.out;
  EXPECT_EQ(read_json(dir / "empty" / "index.json")["empty_dirs"], json::array({"empty"}));
  ASSERT_EQ(mcfbench("run tiny.json --out full", dir).status, 0);
  c = mcfbench("collect full empty --out both.json", dir);
  EXPECT_EQ(c.status, 1) << c.out << c.err;
  c = mcfbench("collect full emtpy --out typo.json", dir);  // a folder that does not exist
  EXPECT_EQ(c.status, 1) << c.out << c.err;
  EXPECT_NE(c.err.find("emtpy: not a folder"), std::string::npos) << c.err;
}

TEST(RunnerCli, CollectAfterAKillBeforeAnyCellFinishedNamesTheMissingCells) {
  const fs::path dir = fresh_dir("collect_killed");
  write_text(dir / "slow.json", R"({
    "name": "slow",
    "defaults": {"mesh": "icosphere:level=4", "steps": 40, "dt": 1e-4, "threads": 1},
    "axes": {"dt": [1e-4, 2e-4, 3e-4, 4e-4, 5e-4, 6e-4, 7e-4]}})");
  const pid_t pid = start_run(dir, "slow.json", "out");
  ASSERT_GT(pid, 0);
  // Kill it as soon as it has planned (before its first cell can finish, on any machine but a
  // very fast one).
  // Planned means published: the plan's temporary file appears first and is renamed into place.
  auto planned = [&] {
    if (!fs::is_directory(dir / "out" / "plans")) return false;
    for (const auto& entry : fs::directory_iterator(dir / "out" / "plans"))
      if (entry.path().extension() == ".json") return true;
    return false;
  };
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!planned() && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ::kill(pid, SIGKILL);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(planned());
  const size_t finished = result_files(dir / "out").size();
  if (finished == 7u) GTEST_SKIP() << "the run finished before it could be killed";
  const Command c = mcfbench("collect out", dir);
  EXPECT_EQ(c.status, 1) << c.out << c.err;
  const std::string missing = std::to_string(7 - finished);
  EXPECT_NE(c.out.find(std::to_string(finished) + " cells found of 7, " + missing + " missing"),
            std::string::npos)
      << c.out;
  EXPECT_NE(
      c.out.find("missing cells (" + missing + "): #" + std::to_string(finished) + " {\"dt\":"),
      std::string::npos)
      << c.out;
  if (7 - finished > 5) {  // the first five are named, the rest counted
    EXPECT_NE(c.out.find("... and " + std::to_string(7 - finished - 5) + " more"),
              std::string::npos)
        << c.out;
  }
}

TEST(RunnerCli, CollectNamesAPlanThatWasNeverPublished) {
  // A run stopped between writing its plan and renaming it leaves only the temporary file.
  const fs::path dir = fresh_dir("collect_unpublished_plan");
  fs::create_directories(dir / "out" / "plans");
  write_text(dir / "out" / "plans" / "slow.json.tmp.999999", "{\"study\": \"slow\", \"cel");
  const Command c = mcfbench("collect out", dir);
  EXPECT_EQ(c.status, 1) << c.out << c.err;
  EXPECT_NE(c.out.find("the run plan was never published"), std::string::npos) << c.out;
  EXPECT_NE(c.out.find("slow.json.tmp.999999"), std::string::npos) << c.out;
  EXPECT_NE(c.out.find("rerun `mcfbench run`"), std::string::npos) << c.out;
}

TEST(RunnerCli, ShardsThenCollect) {
  const fs::path dir = fresh_dir("shards");
  write_text(dir / "tiny.json", tiny_config);
  for (int i = 0; i < 3; ++i) {
    const Command c = mcfbench(
        "run tiny.json --out s" + std::to_string(i) + " --shard " + std::to_string(i) + "/3", dir);
    ASSERT_EQ(c.status, 0) << c.err;
    EXPECT_EQ(result_files(dir / ("s" + std::to_string(i))).size(), 1u);
  }
  Command c = mcfbench("collect s0 s1 --out partial.json", dir);
  EXPECT_NE(c.status, 0) << "a missing cell must be reported";
  EXPECT_NE(c.out.find("1 missing"), std::string::npos) << c.out;
  c = mcfbench("collect s0 s1 s2 --out index.json", dir);
  EXPECT_EQ(c.status, 0) << c.out << c.err;
  const json index = read_json(dir / "index.json");
  EXPECT_EQ(index["files"].size(), 3u);
  EXPECT_EQ(index["studies"][0]["cells_expected"], 3);
  EXPECT_TRUE(index["studies"][0]["missing"].empty());
  // The same cell in two folders is a duplicate.
  fs::copy_file(result_files(dir / "s0")[0], dir / "s1" / result_files(dir / "s0")[0].filename());
  c = mcfbench("collect s0 s1 s2 --out dup.json", dir);
  EXPECT_NE(c.status, 0);
  EXPECT_EQ(read_json(dir / "dup.json")["duplicates"].size(), 1u);
}

TEST(RunnerCli, ConcurrentShardsIntoOneFolderKeepEveryCellAndPlan) {
  // The tasks of a job array write into one folder at once, each its own cells and plan; a shard
  // run twice at once (an array submitted again while the first still ran) writes the same files
  // twice. Neither may lose or damage a cell or a plan: every file is published by a rename of a
  // temporary file named by its machine and process.
  const fs::path dir = fresh_dir("concurrent_shards");
  write_text(dir / "c.json", R"({
    "name": "concurrent",
    "defaults": {"mesh": "icosphere:level=3", "steps": 15, "threads": 1},
    "axes": {"dt": [0.001, 0.002, 0.003, 0.004, 0.005, 0.006]},
    "metrics": {"frames": [15], "reference": {"dt": 0.001}, "distance_samples": 200}})");
  std::string all;
  int n = 0;
  for (const char* shard : {"0/3", "1/3", "2/3", "1/3"}) {
    const std::string name = "process" + std::to_string(n++);
    all += "(" + std::string(MCFBENCH_BINARY) + " run c.json --out out --shard " + shard + " >" +
           name + ".out 2>&1; echo $? >" + name + ".rc) & ";
  }
  const std::string cmd = "cd '" + dir.string() + "' && { " + all + "wait; }";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().extension() != ".rc") continue;
    EXPECT_EQ(slurp(entry.path()), "0\n")
        << entry.path() << ": " << slurp(fs::path(entry.path()).replace_extension(".out"));
  }
  // The distances to a reference cell another shard ran, then the check.
  Command c = mcfbench("run c.json --out out --distances-only", dir);
  ASSERT_EQ(c.status, 0) << c.err;
  c = mcfbench("collect out", dir);
  EXPECT_EQ(c.status, 0) << c.out << c.err;
  EXPECT_NE(c.out.find("6 cells found of 6, 0 missing, 0 duplicated, 0 errored"), std::string::npos)
      << c.out;
  EXPECT_EQ(c.out.find("lack their reference distance"), std::string::npos) << c.out;
  const auto results = result_files(dir / "out");
  ASSERT_EQ(results.size(), 6u);
  for (const fs::path& r : results) EXPECT_EQ(read_json(r)["status"], "ok") << r;
  std::set<std::string> plans;
  for (const auto& entry : fs::directory_iterator(dir / "out" / kPlanFolder)) {
    plans.insert(entry.path().filename().string());
    EXPECT_EQ(read_json(entry.path())["cells"].size(), 6u) << entry.path();
  }
  ASSERT_EQ(plans.size(), 3u);
  for (int i = 0; i < 3; ++i)
    EXPECT_EQ(std::count_if(plans.begin(), plans.end(),
                            [&](const std::string& p) {
                              return p.find(".shard-" + std::to_string(i) + "-of-3.json") !=
                                     std::string::npos;
                            }),
              1)
        << i;
  for (const auto& entry : fs::recursive_directory_iterator(dir / "out"))
    EXPECT_EQ(entry.path().string().find(".tmp."), std::string::npos) << entry.path();
}

TEST(RunnerCli, ConfigErrorsNameFileAndKeyAndWriteNothing) {
  const fs::path dir = fresh_dir("cfgerr");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {R"({"defaults": {"mesh": "icosphere:level=1", "solver": {"cycels": 2}}})",
       "defaults.solver.cycels"},
      {R"({"defaults": {"mesh": "icosphere:level=1"}, "zip": [{"dt": [0.1, 0.2], "steps": [1]}]})",
       "zip[0].steps"},
      {R"({"defaults": {"mesh": "icosphere:level=1"}, "axes": {"octree.deep": [1]}})",
       "axes.octree.deep"},
      {R"({"defaults": {"mesh": "icosphere:level=1"}, "bogus": 1})", "bogus"},
      {R"({"defaults": {"mesh": "icosphere:level=1"}, "axes": {"dt": [0.1]}, "exclude": [{"dtx": 0.1}]})",
       "exclude[0].dtx"},
      {R"({"defaults": {"mesh": "no_such_generator:x=1"}})", "mesh"},
  };
  int n = 0;
  for (const auto& [text, key] : cases) {
    const std::string file = "bad" + std::to_string(n++) + ".json";
    write_text(dir / file, text);
    const Command c = mcfbench("run " + file + " --out out", dir);
    EXPECT_NE(c.status, 0) << text;
    EXPECT_NE(c.err.find(file), std::string::npos) << c.err;
    EXPECT_NE(c.err.find(key), std::string::npos) << c.err;
    EXPECT_FALSE(fs::exists(dir / "out")) << "wrote output for " << text;
  }
  write_text(dir / "tiny.json", tiny_config);
  const Command c = mcfbench("run tiny.json --shard 3/3 --out out", dir);
  EXPECT_NE(c.status, 0);
  EXPECT_NE(c.err.find("--shard"), std::string::npos) << c.err;
  EXPECT_FALSE(fs::exists(dir / "out"));
}

}  // namespace
}  // namespace mcf
