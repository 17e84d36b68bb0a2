// Regression comparison: the Mann–Whitney test, a 2x slowdown flagged (synthetic and on a real
// run's copy), a set compared with itself or with tiny noise stays quiet, accuracy losses are
// flagged, NEW is stored in the history under its machine and commit; samples are per-repetition
// medians of steps 2..N, and sets of different machines, threads or builds are refused.

#include "harness/compare.h"

#include "harness_test_util.h"

#include <cmath>
#include <functional>
#include <random>

namespace mcf {
namespace {

using namespace mcf::test;
using nlohmann::json;

TEST(Compare, MannWhitney) {
  const std::vector<double> a = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10};
  std::vector<double> b;
  for (double x : a) b.push_back(x + 100);
  EXPECT_LT(mann_whitney_p(a, b), 1e-3);
  EXPECT_GT(mann_whitney_p(a, a), 0.9);
  EXPECT_DOUBLE_EQ(mann_whitney_p({1, 1, 1}, {1, 1, 1}), 1.0);  // all tied
  EXPECT_DOUBLE_EQ(mann_whitney_p({}, {1}), 1.0);
  // Reference values: scipy.stats.mannwhitneyu(a, b, method="asymptotic", use_continuity=True).
  EXPECT_NEAR(mann_whitney_p({1, 2, 3, 5, 8}, {4, 6, 7, 9, 10}), 0.09469294259947589, 1e-12);
  EXPECT_NEAR(mann_whitney_p({1, 2, 2, 5, 8, 8}, {2, 6, 8, 9, 10}), 0.16304505585423734,
              1e-12);  // ties
  EXPECT_DOUBLE_EQ(median({3, 1, 2}), 2);
  EXPECT_DOUBLE_EQ(median({4, 1, 3, 2}), 2.5);
}

constexpr int kReps = 5;  // the fewest a side at which the U test can reach p < 0.05 is 4

/// A synthetic result set: 3 cells, kReps repetitions, 15 steps each; per-step seconds scaled by
/// `slow` with multiplicative noise of +-noise; final radial error scaled by `error`.
/// With `steal` >= 0 each cell also records run_seconds 1 and steal_seconds `steal`.
void make_set(const fs::path& dir, const std::string& commit, double slow, double noise,
              double error, unsigned seed, double steal = -1) {
  fs::create_directories(dir);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(1 - noise, 1 + noise);
  for (int cell = 0; cell < 3; ++cell)
    for (int rep = 0; rep < kReps; ++rep) {
      json steps = json::array();
      for (int s = 1; s <= 15; ++s)
        steps.push_back(
            {{"step", s},
             {"seconds",
              {{"total", 0.01 * (cell + 1) * (1 + 0.2 * std::sin(s)) * slow * jitter(rng)}}},
             {"radial_error", {{"rms", 1e-3 * (cell + 1) * s * error}}}});
      const std::string key = "cellkey" + std::to_string(cell);
      json r = {{"status", "ok"},
                {"environment", {{"commit", commit}}},
                {"cell",
                 {{"key", key + "r" + std::to_string(rep)},
                  {"config_key", key},
                  {"index", cell * kReps + rep},
                  {"repetition", rep},
                  {"study", "synthetic"},
                  {"assignment", {{"solver.name", "solver" + std::to_string(cell)}}}}},
                {"steps", steps}};
      if (steal >= 0) {
        r["run_seconds"] = 1.0;
        r["steal_seconds"] = steal;
      }
      std::ofstream(dir / (commit + std::to_string(cell) + std::to_string(rep) + ".json"))
          << r.dump();
    }
}

TEST(CompareCli, ReportsTheHypervisorsStolenShareOfEachSet) {
  // A slower NEW whose cells lost a quarter of their run time to other guests says so; sets
  // without the record show "–", and without it on either side the line is left out.
  const fs::path dir = fresh_dir("compare_steal");
  make_set(dir / "old", "aaaa", 1.0, 0.03, 1.0, 1);
  make_set(dir / "stolen", "bbbb", 2.0, 0.03, 1.0, 2, 0.25);
  make_set(dir / "quiet", "cccc", 1.0, 0.03, 1.0, 3, 0.0);
  Command c = mcfbench("compare old stolen", dir);
  EXPECT_EQ(c.status, 1) << c.out << c.err;  // still a regression: the verdict is the timings'
  EXPECT_NE(c.out.find("per cell run time: OLD –, NEW 25.0%."), std::string::npos) << c.out;
  c = mcfbench("compare quiet stolen", dir);
  EXPECT_NE(c.out.find("OLD 0.0%, NEW 25.0%"), std::string::npos) << c.out;
  c = mcfbench("compare old old", dir);
  EXPECT_EQ(c.out.find("Hypervisor steal"), std::string::npos) << c.out;
}

TEST(CompareCli, FlagsSlowdownAndAccuracyLossOnly) {
  const fs::path dir = fresh_dir("compare");
  make_set(dir / "old", "aaaa", 1.0, 0.03, 1.0, 1);
  make_set(dir / "same", "bbbb", 1.0, 0.03, 1.0, 2);  // a second run of the same code: tiny noise
  make_set(dir / "slow", "cccc", 2.0, 0.03, 1.0, 3);
  make_set(dir / "worse", "dddd", 1.0, 0.03, 1.5, 4);
  Command c = mcfbench("compare old old", dir);
  EXPECT_EQ(c.status, 0) << c.out << c.err;
  EXPECT_NE(c.out.find("3 cells compared, 0 changed"), std::string::npos) << c.out;
  c = mcfbench("compare old same --all", dir);
  EXPECT_EQ(c.status, 0) << c.out << c.err;
  EXPECT_NE(c.out.find("same |"), std::string::npos)
      << "unchanged rows are listed with --all: " << c.out;
  EXPECT_NE(c.out.find("| solver.name=solver2 |"), std::string::npos) << c.out;
  c = mcfbench("compare old slow", dir);
  EXPECT_EQ(c.status, 1) << c.out << c.err;
  EXPECT_NE(c.out.find("solver.name=solver1"), std::string::npos) << c.out;
  EXPECT_NE(c.out.find("**slower**"), std::string::npos) << c.out;
  EXPECT_NE(c.out.find("| 2.0"), std::string::npos) << c.out;  // the ratio column
  c = mcfbench("compare slow old", dir);                       // faster is not a regression
  EXPECT_EQ(c.status, 0) << c.out;
  EXPECT_NE(c.out.find("faster"), std::string::npos) << c.out;
  c = mcfbench("compare old worse --threshold 0.2", dir);
  EXPECT_EQ(c.status, 1) << c.out;
  EXPECT_NE(c.out.find("less accurate"), std::string::npos) << c.out;
  // A folder holding two commits needs DIR@COMMIT.
  for (const auto& f : result_files(dir / "slow")) fs::copy_file(f, dir / "same" / f.filename());
  c = mcfbench("compare old same", dir);
  EXPECT_NE(c.status, 0);
  EXPECT_NE(c.err.find("@COMMIT"), std::string::npos) << c.err;
  c = mcfbench("compare old same@cccc", dir);
  EXPECT_EQ(c.status, 1) << c.out << c.err;
  c = mcfbench("compare old same@bbbb", dir);
  EXPECT_EQ(c.status, 0) << c.out << c.err;
}

TEST(CompareCli, FailedStoppedOrMissingCellsAndAnUnknownMetricAreNotPasses) {
  // A cell that errors has no timings and one that stops early has fewer: neither may pass as
  // "no regression", nor may a cell missing from NEW or a --metric that no step has.
  const fs::path dir = fresh_dir("compare_status");
  make_set(dir / "old", "aaaa", 1.0, 0.03, 1.0, 1);
  auto variant = [&](const std::string& name, const std::function<void(json&)>& edit,
                     const std::string& file) {
    fs::create_directories(dir / name);
    for (const auto& f : result_files(dir / "old")) {
      json r = read_json(f);
      r["environment"]["commit"] = "bbbb";
      if (f.filename().string() == file) edit(r);
      std::ofstream(dir / name / f.filename()) << r.dump();
    }
  };
  variant(
      "errored",
      [](json& r) {
        r["status"] = "error";
        r["stop"] = {{"step", 0}, {"reason", "error: boom"}};
        r["steps"] = json::array();
      },
      "aaaa10.json");
  variant(
      "stopped",
      [](json& r) {
        r["status"] = "singular";
        r["stop"] = {{"step", 5}, {"reason", "collapsed area"}};
        r["steps"].erase(r["steps"].begin() + 5, r["steps"].end());
      },
      "aaaa21.json");
  variant(
      "shorter_ok", [](json& r) { r["steps"].erase(r["steps"].begin() + 5, r["steps"].end()); },
      "aaaa00.json");
  Command c = mcfbench("compare old errored", dir);
  EXPECT_EQ(c.status, 1) << c.out << c.err;
  EXPECT_NE(c.out.find("**failed** (error: error: boom)"), std::string::npos) << c.out;
  EXPECT_NE(c.out.find("REGRESSION"), std::string::npos) << c.out;
  c = mcfbench("compare old stopped", dir);
  EXPECT_EQ(c.status, 1) << c.out << c.err;
  EXPECT_NE(c.out.find("**failed** (singular: collapsed area)"), std::string::npos) << c.out;
  EXPECT_NE(c.out.find("**stopped earlier** (5 of 15 steps)"), std::string::npos) << c.out;
  c = mcfbench("compare old shorter_ok", dir);
  EXPECT_EQ(c.status, 1) << c.out << c.err;
  EXPECT_NE(c.out.find("**stopped earlier** (5 of 15 steps)"), std::string::npos) << c.out;
  // The reverse is not a regression: NEW fixed what OLD got wrong.
  c = mcfbench("compare errored old", dir);
  EXPECT_EQ(c.status, 0) << c.out << c.err;
  // A cell that stopped as singular in OLD (say a pinch) and errors in NEW is still a failure.
  variant(
      "errored_where_stopped",
      [](json& r) {
        r["status"] = "error";
        r["stop"] = {{"step", 0}, {"reason", "error: boom"}};
        r["steps"] = json::array();
      },
      "aaaa21.json");
  c = mcfbench("compare stopped errored_where_stopped", dir);
  EXPECT_EQ(c.status, 1) << c.out << c.err;
  EXPECT_NE(c.out.find("**failed** (error: error: boom)"), std::string::npos) << c.out;
  // A NEW whose every cell errored (no steps at all) is a regression table, not a metric error.
  variant(
      "all_errored", [](json&) {}, "");
  for (const auto& f : result_files(dir / "all_errored")) {
    json r = read_json(f);
    r["status"] = "error";
    r["steps"] = json::array();
    std::ofstream(f) << r.dump();
  }
  c = mcfbench("compare old all_errored", dir);
  EXPECT_EQ(c.status, 1) << c.out << c.err;
  EXPECT_NE(c.out.find("3 cells compared, 3 changed"), std::string::npos) << c.out;
  // A cell missing from NEW.
  variant(
      "missing", [](json&) {}, "");
  for (int rep = 0; rep < kReps; ++rep)
    fs::remove(dir / "missing" / ("aaaa2" + std::to_string(rep) + ".json"));
  c = mcfbench("compare old missing", dir);
  EXPECT_EQ(c.status, 1) << c.out << c.err;
  EXPECT_NE(
      c.out.find("1 cells only in OLD (missing from NEW: a regression): `solver.name=solver2`"),
      std::string::npos)
      << c.out;
  c = mcfbench("compare missing old", dir);  // a cell only in NEW is new work, not a regression
  EXPECT_EQ(c.status, 0) << c.out << c.err;
  // A metric no step has is an error naming it, not "0 changed".
  c = mcfbench("compare old old --metric seconds.totl", dir);
  EXPECT_NE(c.status, 0) << c.out;
  EXPECT_EQ(c.status == 1 && c.out.find("no regression") != std::string::npos, false);
  EXPECT_NE(c.err.find("\"seconds.totl\""), std::string::npos) << c.err;
}

TEST(CompareCli, AccuracyIsTheReferenceDistanceWhereThereIsOne) {
  // Octree-vs-cotangent studies: accuracy is the last distance to the reference flow, which
  // takes precedence over the radial error (here unchanged, so only the distance can flag it).
  const fs::path dir = fresh_dir("compare_distance");
  make_set(dir / "old", "aaaa", 1.0, 0.03, 1.0, 1);
  for (const char* name : {"near", "far"}) {
    fs::create_directories(dir / name);
    for (const auto& f : result_files(dir / "old")) {
      json r = read_json(f);
      r["environment"]["commit"] = name;
      const double d = std::string(name) == "far" ? 2e-3 : 1e-3;
      r["reference_distance"] =
          json::array({{{"step", 1}, {"rms", 9.0}}, {{"step", 15}, {"rms", d}}});
      std::ofstream(dir / name / f.filename()) << r.dump();
    }
  }
  Command c = mcfbench("compare near far --all", dir);
  EXPECT_EQ(c.status, 1) << c.out << c.err;
  EXPECT_NE(c.out.find("| 0.001 | 0.002 | 2.000 | **less accurate**"), std::string::npos) << c.out;
  c = mcfbench("compare far near", dir);
  EXPECT_EQ(c.status, 0) << c.out << c.err;
  EXPECT_NE(c.out.find("more accurate"), std::string::npos) << c.out;
  // NEW without the reference distances OLD has (not filled in after a sharded run, frames
  // lost) was "no regression": it cannot be vouched for. Its radial error is another measure.
  fs::create_directories(dir / "lost");
  for (const auto& f : result_files(dir / "near")) {
    json r = read_json(f);
    r["environment"]["commit"] = "lost";
    r.erase("reference_distance");
    std::ofstream(dir / "lost" / f.filename()) << r.dump();
  }
  c = mcfbench("compare near lost", dir);
  EXPECT_EQ(c.status, 1) << c.out << c.err;
  EXPECT_NE(c.out.find("**accuracy missing** (no reference_distance)"), std::string::npos) << c.out;
  c = mcfbench("compare lost near", dir);  // NEW measures more than OLD did: not a regression
  EXPECT_EQ(c.status, 0) << c.out << c.err;
}

TEST(CompareCli, InjectedSlowdownOnARealRun) {
  const fs::path dir = fresh_dir("compare_real");
  write_text(
      dir / "c.json",
      R"({"name": "c", "repetitions": 4, "defaults": {"mesh": "icosphere:level=3", "steps": 10, "dt": 1e-4, "threads": 1}})");
  Command c = mcfbench("run c.json --out old", dir);
  ASSERT_EQ(c.status, 0) << c.err;
  fs::create_directories(dir / "new");
  // Every new repetition slower than the slowest old one: the real run's repetitions can differ
  // by more than 2x on a loaded machine, so doubling each would not separate the sets.
  double slowest = 0;
  for (const auto& f : result_files(dir / "old")) {
    const json r = read_json(f);
    slowest = std::max(slowest, r["timing"]["step_median_seconds"].get<double>());
    for (const auto& s : r["steps"])
      slowest = std::max(slowest, s["seconds"]["total"].get<double>());
  }
  for (const auto& f : result_files(dir / "old")) {
    json r = read_json(f);
    const double slow = 2 * slowest * (1 + 0.01 * r["cell"]["repetition"].get<int>());
    for (auto& s : r["steps"])
      for (auto& [k, v] : s["seconds"].items()) v = k == "total" ? slow : v.get<double>();
    r["timing"]["step_median_seconds"] = slow;
    std::ofstream(dir / "new" / f.filename()) << r.dump();
  }
  c = mcfbench("compare old new", dir);
  EXPECT_EQ(c.status, 1) << c.out << c.err;
  EXPECT_NE(c.out.find("**slower**"), std::string::npos) << c.out;
  c = mcfbench("compare old old", dir);
  EXPECT_EQ(c.status, 0) << c.out << c.err;
  c = mcfbench("compare old new --metric radial_error.rms", dir);  // same accuracy, other metric
  EXPECT_EQ(c.status, 0) << c.out << c.err;
}

TEST(Compare, SmallestPValueSaysHowManyRepetitionsTheTestNeeds) {
  EXPECT_GE(smallest_mann_whitney_p(3, 3), 0.05);
  EXPECT_LT(smallest_mann_whitney_p(4, 4), 0.05);
  EXPECT_LT(smallest_mann_whitney_p(5, 5), 0.05);
  EXPECT_DOUBLE_EQ(smallest_mann_whitney_p(0, 5), 1.0);
}

/// A copy of `from` under `to` with commit `commit`, each result passed through `edit`.
void copy_set(const fs::path& from, const fs::path& to, const std::string& commit,
              const std::function<void(json&, int rep)>& edit) {
  fs::create_directories(to);
  for (const auto& f : result_files(from)) {
    json r = read_json(f);
    r["environment"]["commit"] = commit;
    edit(r, r["cell"]["repetition"].get<int>());
    std::ofstream(to / f.filename()) << r.dump();
  }
}

TEST(CompareCli, SamplesAreRepetitionsNotSteps) {
  // A slow first step (set-up, first touch) does not count; one repetition is one sample, so a
  // set of 2 repetitions cannot be called slower however many steps it has; the recorded
  // timing.step_median_seconds is the sample where present.
  const fs::path dir = fresh_dir("compare_reps");
  make_set(dir / "old", "aaaa", 1.0, 0.03, 1.0, 1);
  copy_set(dir / "old", dir / "first_slow", "bbbb",
           [](json& r, int) { r["steps"][0]["seconds"]["total"] = 100.0; });
  Command c = mcfbench("compare old first_slow", dir);
  EXPECT_EQ(c.status, 0) << c.out << c.err;
  EXPECT_NE(c.out.find("3 cells compared, 0 changed"), std::string::npos) << c.out;
  // Two repetitions a side, twice as slow: listed as untested, not a regression.
  fs::create_directories(dir / "old2");
  fs::create_directories(dir / "slow2");
  for (const auto& f : result_files(dir / "old")) {
    json r = read_json(f);
    if (r["cell"]["repetition"].get<int>() >= 2) continue;
    std::ofstream(dir / "old2" / f.filename()) << r.dump();
    r["environment"]["commit"] = "cccc";
    for (auto& s : r["steps"]) s["seconds"]["total"] = s["seconds"]["total"].get<double>() * 2;
    std::ofstream(dir / "slow2" / f.filename()) << r.dump();
  }
  c = mcfbench("compare old2 slow2", dir);
  EXPECT_EQ(c.status, 0) << c.out << c.err;
  EXPECT_NE(c.out.find("untested"), std::string::npos) << c.out;
  EXPECT_NE(c.out.find("too few repetitions"), std::string::npos) << c.out;
  // The recorded summary wins over the steps for seconds.total, not for another metric.
  copy_set(dir / "old", dir / "summary_slow", "dddd", [](json& r, int) {
    r["timing"] = {{"step_median_seconds", 10.0}};
  });
  c = mcfbench("compare old summary_slow", dir);
  EXPECT_EQ(c.status, 1) << c.out << c.err;
  EXPECT_NE(c.out.find("**slower**"), std::string::npos) << c.out;
  // Contended repetitions are counted per set (the line is left out when neither records it).
  EXPECT_EQ(c.out.find("contended"), std::string::npos) << c.out;
  copy_set(dir / "old", dir / "busy", "eeee", [](json& r, int rep) {
    r["contention"] = {{"contended", rep < 2}};
  });
  c = mcfbench("compare old busy", dir);
  EXPECT_NE(c.out.find("(contended): OLD –, NEW 6 of 15."), std::string::npos) << c.out;
}

TEST(CompareCli, RefusesDifferentMachinesThreadsOrBuilds) {
  const fs::path dir = fresh_dir("compare_machine");
  const json env = {{"cpu", "AMD EPYC"},
                    {"cores", 2},
                    {"threads", 2},
                    {"blas_threads", 2},
                    {"build", {{"type", "Release"}, {"compiler", "GNU 12"}}},
                    {"hostname", "a"}};
  make_set(dir / "raw", "aaaa", 1.0, 0.03, 1.0, 1);
  const auto with = [&](const std::string& key, const json& value) {
    return [=](json& r, int) {
      const std::string commit = r["environment"]["commit"];
      r["environment"] = env;
      r["environment"]["commit"] = commit;
      if (!key.empty()) r["environment"][key] = value;
    };
  };
  copy_set(dir / "raw", dir / "old", "aaaa", with("", nullptr));
  copy_set(dir / "raw", dir / "other_host", "bbbb", with("hostname", "b"));
  copy_set(dir / "raw", dir / "one_thread", "cccc", with("threads", 1));
  copy_set(dir / "raw", dir / "intel", "dddd", with("cpu", "Intel Xeon"));
  copy_set(dir / "raw", dir / "debug", "eeee",
           with("build", {{"type", "Debug"}, {"compiler", "GNU 12"}}));
  Command c = mcfbench("compare old other_host", dir);  // a host name alone is no difference
  EXPECT_EQ(c.status, 0) << c.out << c.err;
  for (const char* other : {"one_thread", "intel", "debug"}) {
    c = mcfbench(std::string("compare old ") + other, dir);
    EXPECT_NE(c.status, 0) << other;
    EXPECT_EQ(c.out.find("regression"), std::string::npos) << other << ": an error, not a verdict";
    EXPECT_NE(c.err.find("--allow-cross-machine"), std::string::npos) << c.err;
  }
  EXPECT_NE(mcfbench("compare old one_thread", dir).err.find("threads: 2 vs 1"), std::string::npos);
  c = mcfbench("compare old intel --allow-cross-machine", dir);
  EXPECT_EQ(c.status, 0) << c.out << c.err;
  EXPECT_NE(c.out.find("Cross-machine comparison"), std::string::npos) << c.out;
  // Repetitions of one cell from two machines in one folder are not pooled either.
  copy_set(dir / "raw", dir / "mixed", "ffff",
           [&](json& r, int rep) { with(rep == 0 ? "cpu" : "", "Intel Xeon")(r, rep); });
  c = mcfbench("compare old mixed", dir);
  EXPECT_NE(c.status, 0);
  EXPECT_NE(c.err.find("different machines"), std::string::npos) << c.err;
}

TEST(CompareCli, HistoryStoresNewUnderItsMachineAndCommit) {
  // --history stores NEW in the history store (`mcfbench history add`): under its machine (the
  // identity, not the host name), its study and its commit, with the commit's parents from the
  // git repository of the current folder, one sample per repetition. A commit that the
  // repository does not have is refused, naming the store.
  const fs::path dir = fresh_dir("compare_history");
  const std::string git = "cd '" + dir.string() +
                          "' && GIT_CONFIG_GLOBAL=/dev/null GIT_CONFIG_NOSYSTEM=1 git -c "
                          "user.name=t -c user.email=t@t ";
  ASSERT_EQ(std::system((git + "init -q && " + git + "commit -q --allow-empty -m one && " + git +
                         "commit -q --allow-empty -m two && " + git + "rev-parse HEAD > head.txt")
                            .c_str()),
            0);
  std::string head = slurp(dir / "head.txt");
  head = head.substr(0, head.find('\n'));
  make_set(dir / "raw", head.substr(0, 12), 1.0, 0.03, 1.0, 1);
  const json env = {{"cpu", "AMD EPYC"}, {"cores", 2}, {"threads", 2}, {"hostname", "a"}};
  copy_set(dir / "raw", dir / "new", head.substr(0, 12), [&](json& r, int) {
    const std::string commit = r["environment"]["commit"];
    r["environment"] = env;
    r["environment"]["commit"] = commit;
  });
  copy_set(dir / "new", dir / "old", "aaaa", [](json&, int) {});
  Command c = mcfbench("compare old new --history store", dir);
  ASSERT_EQ(c.status, 0) << c.out << c.err;
  EXPECT_NE(c.out.find("history: stored " + head), std::string::npos) << c.out;
  std::vector<fs::path> entries;
  for (const auto& m : fs::directory_iterator(dir / "store"))
    if (fs::exists(m.path() / "synthetic" / (head + ".json")))
      entries.push_back(m.path() / "synthetic" / (head + ".json"));
  ASSERT_EQ(entries.size(), 1u);
  const json entry = read_json(entries[0]);
  EXPECT_EQ(entry["parents"].size(), 1u);
  EXPECT_EQ(entry["benchmarks"]["solver.name=solver0"]["samples"].size(), size_t(kReps));
  const json machine = read_json(entries[0].parent_path().parent_path() / "machine.json");
  EXPECT_EQ(machine["cpu"], "AMD EPYC");
  EXPECT_FALSE(machine.contains("hostname"));
  c = mcfbench("compare new old --history store", dir);  // "aaaa" is no commit of the repository
  EXPECT_NE(c.status, 0);
  EXPECT_NE(c.err.find("--history: storing old (aaaa) in store failed"), std::string::npos)
      << c.err;
}

}  // namespace
}  // namespace mcf
