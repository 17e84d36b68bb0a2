#include "harness/compare.h"

#include "harness/history_tool.h"
#include "harness/json_path.h"
#include "harness/subprocess.h"
#include "harness/timing_summary.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

namespace mcf {

using nlohmann::json;

double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  const size_t n = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + long(n), v.end());
  if (v.size() % 2) return v[n];
  const double hi = v[n];
  return 0.5 * (hi + *std::max_element(v.begin(), v.begin() + long(n)));
}

namespace {

/// The fields of a result's `environment` that its timings depend on besides the code: `cpu`,
/// `cores`, `threads`, `blas_threads`, `build` and `libraries` (not the host name: identical
/// machines of a CI pool have different names). Absent fields are left out.
json machine_identity(const json& result) {
  json id = json::object();
  if (!result.is_object() || !result.contains("environment") || !result["environment"].is_object())
    return id;
  const json& env = result["environment"];
  for (const char* k : {"cpu", "cores", "threads", "blas_threads", "build", "libraries"})
    if (env.contains(k)) id[k] = env[k];
  return id;
}

/// The first field that two identities both have and disagree on, as "threads: 2 vs 1"; empty
/// when they agree on every field they share.
std::string identity_difference(const json& a, const json& b) {
  for (auto it = a.begin(); it != a.end(); ++it)
    if (b.contains(it.key()) && b[it.key()] != *it)
      return it.key() + ": " + it->dump() + " vs " + b[it.key()].dump();
  return "";
}

}  // namespace

double smallest_mann_whitney_p(int n1, int n2) {
  if (n1 <= 0 || n2 <= 0) return 1.0;
  std::vector<double> a, b;
  for (int i = 0; i < n1; ++i) a.push_back(i);
  for (int i = 0; i < n2; ++i) b.push_back(n1 + i);
  return mann_whitney_p(a, b);
}

namespace {

namespace fs = std::filesystem;

std::string label_of(const json& assignment, const std::string& key) {
  if (!assignment.is_object() || assignment.empty()) return key;
  std::string s;
  for (auto it = assignment.begin(); it != assignment.end(); ++it) {
    if (!s.empty()) s += " ";
    s += it.key() + "=" + (it->is_string() ? it->get<std::string>() : it->dump());
  }
  return s;
}

/// The accuracy measures in the order compare prefers them: the last distance to the reference
/// flow where a study computes one (octree vs cotangent studies), else the final RMS radial
/// error against the analytic sphere.
constexpr const char* kAccuracyKinds[] = {"reference_distance", "radial_error"};

/// A result's accuracy by one of kAccuracyKinds (NaN when it does not record that one).
double accuracy_of(const json& r, const std::string& kind) {
  if (kind == "reference_distance") {
    if (r.contains("reference_distance") && r["reference_distance"].is_array() &&
        !r["reference_distance"].empty())
      return r["reference_distance"].back().value("rms", NAN);
  } else if (r.contains("steps")) {
    for (auto it = r["steps"].rbegin(); it != r["steps"].rend(); ++it)
      if (it->contains("radial_error")) return (*it)["radial_error"].value("rms", NAN);
  }
  return NAN;
}

std::string fmt(double v, const char* f = "%.4g") {
  if (!std::isfinite(v)) return "–";
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

/// The commit a result was computed by ("unknown" when it does not say).
std::string commit_of(const json& r) {
  return r.contains("environment") ? r["environment"].value("commit", "unknown") : "unknown";
}

/// The cell results of `dir` (sorted by file name) of the commits `commit_filter` begins
/// (all when empty); a file that does not parse throws.
std::vector<json> read_cell_results(const std::string& dir, const std::string& commit_filter) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.is_regular_file() && entry.path().extension() == ".json" &&
        entry.path().filename() != "index.json")
      files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  std::vector<json> results;
  for (const auto& f : files) {
    std::ifstream in(f);
    json r;
    try {
      r = json::parse(in);
    } catch (const json::parse_error& e) {
      throw std::runtime_error(f.string() + ": JSON parse error: " + e.what());
    }
    if (!r.is_object() || !r.contains("cell")) continue;  // not a cell result
    if (!commit_filter.empty() && commit_of(r).rfind(commit_filter, 0) != 0) continue;
    results.push_back(std::move(r));
  }
  return results;
}

/// One repetition's sample of `metric` (NaN when it has none): the median over steps 2..N, so
/// that step 1's first-touch costs (page faults, the first factorization) do not count, and one
/// number per run, so that a cell's samples vary as whole runs do.
double repetition_sample(const json& r, const std::string& metric) {
  if (metric == "seconds.total") {
    const json* t = json_at_path(r, "timing.step_median_seconds");
    if (t && t->is_number()) return t->get<double>();
  }
  return median_after_first_step(r, metric);
}

/// Adds one repetition's result to its cell's samples; returns its number of steps.
int add_repetition(const json& r, const std::string& metric, ResultSet& set) {
  const json& cell = r["cell"];
  const std::string key = cell.value("config_key", cell.value("key", ""));
  CellSamples& c = set.cells[key];
  c.label = label_of(cell.value("assignment", json::object()), key);
  ++c.repetitions;
  const std::string status = r.value("status", "error");
  if (status == "error") ++c.errored;
  if (status != "ok") {
    if (c.failed++ == 0) {
      std::string reason =
          r.contains("stop") && r["stop"].is_object() ? r["stop"].value("reason", "") : "";
      c.failure = status + (reason.empty() ? "" : ": " + reason);
    }
  }
  const int steps = r.contains("steps") && r["steps"].is_array() ? int(r["steps"].size()) : 0;
  c.min_steps = c.min_steps < 0 ? steps : std::min(c.min_steps, steps);
  if (const double v = repetition_sample(r, metric); std::isfinite(v)) c.values.push_back(v);
  const json identity = machine_identity(r);
  if (c.repetitions == 1)
    c.identity = identity;
  else if (!identity_difference(c.identity, identity).empty())
    c.mixed_identity = true;
  for (const char* kind : kAccuracyKinds)
    if (const double e = accuracy_of(r, kind); std::isfinite(e)) c.errors[kind].push_back(e);
  if (const json* k = json_at_path(r, "contention.contended"); k && k->is_boolean()) {
    ++set.contention_recorded;
    set.contended += k->get<bool>() ? 1 : 0;
  }
  const json* run = json_at_path(r, "run_seconds");
  const json* steal = json_at_path(r, "steal_seconds");
  if (run && steal && run->is_number() && steal->is_number()) {
    set.run_seconds += run->get<double>();
    set.steal_seconds += steal->get<double>();
  }
  return steps;
}

}  // namespace

double mann_whitney_p(const std::vector<double>& a, const std::vector<double>& b) {
  const double n1 = double(a.size()), n2 = double(b.size());
  if (a.empty() || b.empty()) return 1.0;
  std::vector<std::pair<double, int>> all;
  for (double x : a) all.push_back({x, 0});
  for (double x : b) all.push_back({x, 1});
  std::sort(all.begin(), all.end());
  // Mid-ranks for ties; the tie term Σ(t³ - t) corrects the variance.
  double rank_sum_a = 0, ties = 0;
  for (size_t i = 0; i < all.size();) {
    size_t j = i;
    while (j < all.size() && all[j].first == all[i].first) ++j;
    const double t = double(j - i), mid = 0.5 * double(i + 1 + j);
    ties += t * t * t - t;
    for (size_t k = i; k < j; ++k)
      if (all[k].second == 0) rank_sum_a += mid;
    i = j;
  }
  const double n = n1 + n2;
  const double u = rank_sum_a - n1 * (n1 + 1) / 2;
  const double mean = n1 * n2 / 2;
  const double var = n1 * n2 / 12 * ((n + 1) - ties / (n * (n - 1)));
  if (!(var > 0)) return 1.0;
  const double z = std::max(0.0, std::abs(u - mean) - 0.5) / std::sqrt(var);
  return std::erfc(z / std::sqrt(2.0));
}

namespace {

/// Reads DIR[@COMMIT]: every cell result (*.json with a "cell" object) in DIR, keeping only
/// those of COMMIT (a prefix) when given. A folder holding several commits without @COMMIT is
/// an error listing them (timings of different code must not be pooled). `metric` is the
/// dotted path of the per-step value ("seconds.total", "radial_error.rms", ...).
/// When cells have steps but none of them has `metric` (a misspelt --metric), that is an error.
ResultSet load_result_set(const std::string& dir_at_commit, const std::string& metric) {
  ResultSet set;
  std::string commit_filter;
  set.dir = dir_at_commit;
  if (!fs::is_directory(set.dir)) {
    const auto at = dir_at_commit.rfind('@');
    if (at != std::string::npos) {
      set.dir = dir_at_commit.substr(0, at);
      commit_filter = dir_at_commit.substr(at + 1);
    }
  }
  if (!fs::is_directory(set.dir))
    throw std::runtime_error(dir_at_commit + ": not a results folder");
  const std::vector<json> results = read_cell_results(set.dir, commit_filter);
  if (results.empty())
    throw std::runtime_error(dir_at_commit + ": no cell results" +
                             (commit_filter.empty() ? "" : " of commit " + commit_filter));
  std::set<std::string> commits, studies;
  for (const json& r : results) {
    commits.insert(commit_of(r));
    studies.insert(r["cell"].value("study", ""));
  }
  if (commits.size() > 1) {
    std::string list;
    for (const auto& c : commits) list += " " + c;
    throw std::runtime_error(dir_at_commit + ": holds results of " +
                             std::to_string(commits.size()) + " commits (" + list.substr(1) +
                             "); pick one as " + set.dir + "@COMMIT");
  }
  set.commit = *commits.begin();
  set.study = *studies.begin();
  bool any_steps = false;
  for (const json& r : results) any_steps = add_repetition(r, metric, set) > 0 || any_steps;
  // Cells with steps but not one value: the metric's name is wrong. (Cells without any step,
  // all errored, are compared as failures instead.)
  bool any_value = false;
  for (const auto& [key, c] : set.cells) any_value = any_value || !c.values.empty();
  if (any_steps && !any_value)
    throw std::runtime_error(dir_at_commit + ": no step of any cell has the metric \"" + metric +
                             "\" (--metric is a dotted path in steps[], e.g. seconds.total, "
                             "seconds.solve, radial_error.rms)");
  return set;
}

/// Throws (naming the cell and the field) when a matched cell's identity differs between the
/// sets, or within one set, unless o.allow_cross_machine.
CompareReport compare_results(const ResultSet& old_set, const ResultSet& new_set,
                              const CompareOptions& o) {
  CompareReport rep;
  for (const auto& [key, n] : new_set.cells) {
    auto it = old_set.cells.find(key);
    if (it == old_set.cells.end()) {
      rep.only_new.push_back(n.label);
      continue;
    }
    const CellSamples& old = it->second;
    // Timings of different machines, thread counts or builds differ for reasons other than the
    // code; so do the repetitions of one cell taken on different machines.
    for (const CellSamples* s : {&old, &n})
      if (s->mixed_identity && !o.allow_cross_machine)
        throw std::runtime_error("cell `" + n.label + "`: its repetitions in " +
                                 (s == &old ? old_set.dir : new_set.dir) +
                                 " ran on different machines, thread counts or builds "
                                 "(--allow-cross-machine compares them anyway)");
    if (const std::string d = identity_difference(old.identity, n.identity); !d.empty()) {
      if (!o.allow_cross_machine)
        throw std::runtime_error("cell `" + n.label + "` ran on different machines, thread " +
                                 "counts or builds in OLD and NEW (" + d +
                                 "); timings across machines do not measure the code "
                                 "(--allow-cross-machine compares them anyway)");
      rep.cross_machine.push_back(n.label + ": " + d);
    }
    CellComparison c;
    c.key = key;
    c.label = n.label;
    c.n_old = int(old.values.size());
    c.n_new = int(n.values.size());
    c.old_median = median(old.values);
    c.new_median = median(n.values);
    c.ratio = c.old_median > 0 ? c.new_median / c.old_median : NAN;
    c.p_value = mann_whitney_p(old.values, n.values);
    c.untestable = smallest_mann_whitney_p(c.n_old, c.n_new) >= o.alpha;
    c.slower = std::isfinite(c.ratio) && c.ratio > 1 + o.threshold && c.p_value < o.alpha;
    c.faster = std::isfinite(c.ratio) && c.ratio < 1 / (1 + o.threshold) && c.p_value < o.alpha;
    c.failed = (n.failed > 0 && old.failed == 0) || (n.errored > 0 && old.errored == 0);
    // The first measure OLD has decides: compared when NEW has it too, else NEW's accuracy is
    // missing (reference distances not filled in after a sharded run, frames lost), where it
    // used to pass unremarked. A measure only NEW has is new work, not a regression.
    const std::vector<double>* old_errors = nullptr;
    const std::vector<double>* new_errors = nullptr;
    for (const char* kind : kAccuracyKinds) {
      const auto o_it = old.errors.find(kind);
      if (o_it == old.errors.end()) continue;
      const auto n_it = n.errors.find(kind);
      if (n_it == n.errors.end()) {
        c.accuracy_missing = !c.failed;  // a failed NEW is flagged as that already
        c.missing_accuracy = kind;
      } else {
        old_errors = &o_it->second;
        new_errors = &n_it->second;
      }
      break;
    }
    if (old_errors && new_errors) {
      c.has_error = true;
      c.old_error = median(*old_errors);
      c.new_error = median(*new_errors);
      // Errors at round-off level are noise, not accuracy: a floor keeps 1e-16 vs 3e-16 quiet.
      const double floor = 1e-12;
      c.error_ratio = std::max(c.new_error, floor) / std::max(c.old_error, floor);
      c.less_accurate = c.error_ratio > 1 + o.threshold;
    }
    c.old_steps = std::max(old.min_steps, 0);
    c.new_steps = std::max(n.min_steps, 0);
    c.failure = n.failure;
    c.stopped_earlier = c.new_steps < c.old_steps;
    rep.regression = rep.regression || c.slower || c.less_accurate || c.failed ||
                     c.stopped_earlier || c.accuracy_missing;
    rep.cells.push_back(std::move(c));
  }
  for (const auto& [key, old] : old_set.cells)
    if (!new_set.cells.count(key)) rep.only_old.push_back(old.label);
  // A cell that vanished from NEW (not run, or its file lost) cannot be vouched for.
  rep.regression = rep.regression || !rep.only_old.empty();
  return rep;
}

std::string compare_markdown(const CompareReport& r, const ResultSet& old_set,
                             const ResultSet& new_set, const CompareOptions& o) {
  std::ostringstream md;
  md << "## compare " << old_set.dir << " (" << old_set.commit << ") → " << new_set.dir << " ("
     << new_set.commit << ")\n\n";
  md << "Metric `" << o.metric
     << "`: one sample per repetition (its median step after the first), median over "
     << "repetitions; Mann–Whitney U over the repetitions, slower/faster when the ratio passes 1±"
     << o.threshold << " with p < " << o.alpha
     << "; accuracy = final reference distance or radial error (RMS).\n\n";
  int untestable = 0;
  for (const auto& c : r.cells) untestable += c.untestable ? 1 : 0;
  if (untestable)
    md << untestable << " cells have too few repetitions for the U test to reach p < " << o.alpha
       << " (at least 4 a side are needed, 5 or more recommended): their timings cannot be "
          "called slower or faster (marked `untested`).\n\n";
  if (!r.cross_machine.empty()) {
    md << "**Cross-machine comparison** (--allow-cross-machine): " << r.cross_machine.size()
       << " cells ran on different machines, thread counts or builds, e.g. "
       << r.cross_machine.front() << ".\n\n";
  }
  if (old_set.run_seconds > 0 || new_set.run_seconds > 0) {
    // Stolen time is CPU time of all vCPUs, run time is wall time: on a 2-vCPU guest the share
    // can reach 200%. A slower NEW with a much larger share may be the machine, not the code.
    const auto share = [](const ResultSet& s) {
      return s.run_seconds > 0 ? fmt(100 * s.steal_seconds / s.run_seconds, "%.1f") + "%"
                               : std::string("–");
    };
    md << "Hypervisor steal (CPU time the host gave other guests, all vCPUs) per cell run time: "
          "OLD "
       << share(old_set) << ", NEW " << share(new_set) << ".\n\n";
  }
  if (old_set.contention_recorded > 0 || new_set.contention_recorded > 0) {
    // A verdict on sets that shared the machine may be the machine's: said, not overridden.
    const auto share = [](const ResultSet& s) {
      return s.contention_recorded > 0
                 ? std::to_string(s.contended) + " of " + std::to_string(s.contention_recorded)
                 : std::string("–");
    };
    md << "Repetitions that shared the machine with other work (contended): OLD " << share(old_set)
       << ", NEW " << share(new_set) << ".\n\n";
  }
  int changed = 0;
  std::ostringstream table;
  table << "| cell | old | new | new/old | p | old error | new error | error ratio | verdict |\n"
        << "|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& c : r.cells) {
    std::string verdict;
    if (c.slower) verdict += "**slower** ";
    if (c.faster) verdict += "faster ";
    if (c.untestable && std::isfinite(c.ratio) &&
        (c.ratio > 1 + o.threshold || c.ratio < 1 / (1 + o.threshold)))
      verdict += "untested ";
    if (c.less_accurate) verdict += "**less accurate** ";
    if (c.has_error && c.error_ratio < 1 / (1 + o.threshold)) verdict += "more accurate ";
    if (c.failed) verdict += "**failed** (" + c.failure + ") ";
    if (c.accuracy_missing) verdict += "**accuracy missing** (no " + c.missing_accuracy + ") ";
    if (c.stopped_earlier)
      verdict += "**stopped earlier** (" + std::to_string(c.new_steps) + " of " +
                 std::to_string(c.old_steps) + " steps) ";
    if (!verdict.empty()) ++changed;
    if (verdict.empty() && !o.show_all) continue;
    table << "| " << c.label << " | " << fmt(c.old_median) << " | " << fmt(c.new_median) << " | "
          << fmt(c.ratio, "%.3f") << " | " << fmt(c.p_value, "%.2g") << " | "
          << (c.has_error ? fmt(c.old_error) : "–") << " | "
          << (c.has_error ? fmt(c.new_error) : "–") << " | "
          << (c.has_error ? fmt(c.error_ratio, "%.3f") : "–") << " | "
          << (verdict.empty() ? "same " : verdict) << "|\n";
  }
  if (changed || (o.show_all && !r.cells.empty())) md << table.str() << "\n";
  md << r.cells.size() << " cells compared, " << changed << " changed, "
     << (r.cells.size() - size_t(changed)) << " unchanged.\n";
  if (!r.only_old.empty()) {
    md << r.only_old.size() << " cells only in OLD (missing from NEW: a regression):";
    for (size_t i = 0; i < r.only_old.size() && i < 5; ++i) md << " `" << r.only_old[i] << "`";
    if (r.only_old.size() > 5) md << " …";
    md << "\n";
  }
  if (!r.only_new.empty()) md << r.only_new.size() << " cells only in NEW.\n";
  md << (r.regression ? "REGRESSION\n" : "no regression\n");
  return md.str();
}

void store_in_history(const ResultSet& set, const std::string& store) {
  // The history store keys the set by machine, commit and config (reports/perf_history.py
  // `add`), as `history run` does; the commit's date and parents come from the git repository of
  // the current folder.
  const ProgramResult r = run_program({"/usr/bin/python3", history_script(), "add",
                                       set.study.empty() ? std::string("compare") : set.study,
                                       set.dir, "--store", store, "--commit", set.commit});
  std::printf("%s", r.out.c_str());
  if (!r.ok())
    throw std::runtime_error("--history: storing " + set.dir + " (" + set.commit + ") in " + store +
                             " failed" +
                             (r.start_error.empty() ? " (exit " + std::to_string(r.status) + ")"
                                                    : ": " + r.start_error));
}

}  // namespace

int compare_and_record(const CompareRequest& request) {
  const CompareOptions& o = request.options;
  const ResultSet old_set = load_result_set(request.old_dir, o.metric);
  const ResultSet new_set = load_result_set(request.new_dir, o.metric);
  const CompareReport r = compare_results(old_set, new_set, o);
  std::printf("%s", compare_markdown(r, old_set, new_set, o).c_str());
  if (request.store_history)
    store_in_history(new_set, request.history.empty() ? "data/history" : request.history);
  return r.regression ? 1 : 0;
}

}  // namespace mcf
