// `mcfbench collect DIR...`: merge result folders (e.g. the shards of a Slurm array) into one
// index file and check them against the matrix `run` planned (DIR/plans/, written before its
// first cell) or, for folders without a plan, the matrix stored in the results: every cell
// present once. A folder holding neither results nor a plan is an error, not an empty success.

#include "bench/experiment_config.h"
#include "bench/runner.h"
#include "core/atomic_file.h"
#include "flows/config_reader.h"
#include "tools/commands.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <set>

namespace mcf {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct CollectArgs {
  std::vector<std::string> dirs;
  std::string out;
};

struct Group {  // results of one study variant at one commit
  json study_config;
  std::string study, commit, source;
  bool quick = false;
  std::map<int, std::vector<std::string>> files_by_index;
  std::vector<int> without_distance;  ///< candidates; reference cells themselves are filtered below
  std::vector<int> errored;           ///< cells whose result is {"status": "error"}
  std::map<int, json> planned;     ///< index -> {repetition, assignment[, hash]} from `run`'s plans
  std::vector<std::string> plans;  ///< the plan files read
};

std::string group_name(const std::string& study, bool quick, const std::string& commit) {
  return study + (quick ? "-quick" : "") + "@" + commit;
}

/// The JSON in `path`, or nothing when it does not parse: then it is listed in `unreadable` and
/// named on stdout with what to do (`remedy`). Files not written by the atomic writer (a copy
/// cut short, an editor) are the cause; `mcfbench run` rewrites them on its next pass.
std::optional<json> read_or_list(const fs::path& path, json& unreadable, const char* remedy) {
  try {
    std::ifstream in(path);
    return json::parse(in);
  } catch (const json::parse_error& e) {
    unreadable.push_back({{"file", path.string()}, {"error", e.what()}});
    std::printf("%s: unreadable (%s); %s\n", path.c_str(), e.what(), remedy);
    return std::nullopt;
  }
}

/// The `.json` files directly in `dir` (none if it is not a folder), but `index.json`, sorted.
std::vector<fs::path> json_files(const fs::path& dir) {
  std::vector<fs::path> paths;
  if (fs::is_directory(dir))
    for (const auto& entry : fs::directory_iterator(dir))
      if (entry.is_regular_file() && entry.path().extension() == ".json" &&
          entry.path().filename() != "index.json")
        paths.push_back(entry.path());
  std::sort(paths.begin(), paths.end());
  return paths;
}

/// A plan's temporary file (`NAME.json.tmp.PID`, see write_file_atomic) in `plans`, if any.
std::optional<fs::path> temporary_plan(const fs::path& plans) {
  if (!fs::is_directory(plans)) return std::nullopt;
  for (const auto& entry : fs::directory_iterator(plans))
    if (entry.path().filename().string().find(".json.tmp.") != std::string::npos)
      return entry.path();
  return std::nullopt;
}

/// "#3 {"dt":0.001} rep 1 (ab12cd34ef56.json)": a cell named as a user can find it.
std::string describe_cell(int index, const json& c) {
  std::string s = "#" + std::to_string(index);
  if (c.contains("assignment") && !c["assignment"].empty()) s += " " + c["assignment"].dump();
  if (c.value("repetition", 0) != 0) s += " rep " + std::to_string(c.value("repetition", 0));
  if (c.contains("hash")) s += " (" + c["hash"].get<std::string>() + ".json)";
  return s;
}

}  // namespace

void add_collect_command(CLI::App& app, std::function<int()>& run) {
  auto a = std::make_shared<CollectArgs>();
  CLI::App* cmd = app.add_subcommand(
      "collect",
      "Merge result folders (shards) into an index file; check for missing and duplicate cells.");
  cmd->add_option("dirs", a->dirs, "Result folders")->required();
  cmd->add_option("--out", a->out, "Index file (default FIRST_DIR/index.json)");
  cmd->callback([a, &run] {
    run = [a]() -> int {
      json files = json::array();
      std::map<std::string, Group> groups;
      std::set<std::string> seen_hash;
      json duplicates = json::array(), unreadable = json::array(), empty_dirs = json::array();
      for (const auto& dir : a->dirs) {
        if (!fs::is_directory(dir)) throw std::runtime_error(dir + ": not a folder");
        size_t found = 0;  // cell results, unreadable files and plans in this folder
        // The plans `run` wrote before its first cell: the cells owed even if none finished.
        for (const auto& path : json_files(fs::path(dir) / kPlanFolder)) {
          const std::optional<json> read =
              read_or_list(path, unreadable, "rerun `mcfbench run` to rewrite it");
          if (!read) {
            ++found;
            continue;
          }
          const json& p = *read;
          if (!p.is_object() || !p.contains("cells") || !p["cells"].is_array()) continue;
          ++found;
          const bool quick = p.value("quick", false);
          Group& g = groups[group_name(p.value("study", ""), quick, p.value("commit", "unknown"))];
          g.study = p.value("study", "");
          g.commit = p.value("commit", "unknown");
          g.quick = quick;
          if (g.study_config.is_null() && p.contains("study_config")) {
            g.study_config = p["study_config"];
            g.source = path.string() + " (study_config)";
          }
          g.plans.push_back(path.string());
          for (const json& c : p["cells"]) {
            json& known = g.planned[c.value("index", -1)];
            if (known.is_null() || (!known.contains("hash") && c.contains("hash"))) known = c;
          }
        }
        for (const auto& path : json_files(dir)) {
          const std::optional<json> read =
              read_or_list(path, unreadable, "rerun `mcfbench run` to redo its cell");
          if (!read) {
            ++found;
            continue;
          }
          const json& r = *read;
          if (!r.is_object() || !r.contains("cell")) continue;
          ++found;
          const json& c = r["cell"];
          const std::string commit =
              r.contains("environment") ? r["environment"].value("commit", "unknown") : "unknown";
          const std::string hash = c.value("hash", path.stem().string());
          json entry = {{"file", path.string()},
                        {"hash", hash},
                        {"key", c.value("key", "")},
                        {"config_key", c.value("config_key", "")},
                        {"index", c.value("index", -1)},
                        {"repetition", c.value("repetition", 0)},
                        {"study", c.value("study", "")},
                        {"quick", c.value("quick", false)},
                        {"commit", commit},
                        {"status", r.value("status", "")},
                        {"assignment", c.value("assignment", json::object())}};
          if (r.contains("frames"))
            entry["frames"] = (path.parent_path() / r["frames"].value("dir", "")).string();
          files.push_back(entry);
          // The same hash in two folders is the same cell computed twice (overlapping shards).
          if (!seen_hash.insert(hash).second)
            duplicates.push_back({{"hash", hash}, {"file", path.string()}});
          Group& g = groups[group_name(entry["study"], entry["quick"], commit)];
          if (g.study_config.is_null() && r.contains("study_config")) {
            g.study_config = r["study_config"];
            g.source = path.string() + " (study_config)";
          }
          g.study = entry["study"];
          g.commit = commit;
          g.quick = entry["quick"];
          g.files_by_index[entry["index"].get<int>()].push_back(path.string());
          if (entry["status"] == "error") g.errored.push_back(entry["index"].get<int>());
          // Cells of a study with a reference flow that still lack their distances (their
          // reference was not finished when they ran; an unsharded rerun fills them in).
          if (r.contains("study_config") && r["study_config"].contains("metrics") &&
              r["study_config"]["metrics"].contains("reference") &&
              !r.contains("reference_distance") && !r.contains("reference_cell") &&
              r.value("status", "") != "error")
            g.without_distance.push_back(c.value("index", -1));
        }
        if (found == 0) {
          // A mistyped shard folder, or a run killed before it planned anything: nothing here
          // says which cells were meant, so nothing here can vouch that they are all there. A
          // plan's temporary file alone means the run was stopped while publishing its plan.
          empty_dirs.push_back(dir);
          const std::optional<fs::path> partial = temporary_plan(fs::path(dir) / kPlanFolder);
          if (partial)
            std::printf(
                "%s: no cell results, and the run plan was never published (%s is its unfinished "
                "temporary "
                "file): the run was stopped while planning; rerun `mcfbench run` into this "
                "folder\n",
                dir.c_str(), partial->string().c_str());
          else
            std::printf(
                "%s: no cell results and no run plan (%s/): not a folder `mcfbench run` wrote "
                "into\n",
                dir.c_str(), kPlanFolder);
        }
      }
      json studies = json::array();
      bool problems = !duplicates.empty() || !unreadable.empty() || !empty_dirs.empty();
      for (auto& [name, g] : groups) {
        json s = {{"study", g.study},
                  {"quick", g.quick},
                  {"commit", g.commit},
                  {"cells_found", g.files_by_index.size()}};
        json missing = json::array(), dup = json::array();
        for (const auto& [index, list] : g.files_by_index)
          if (list.size() > 1) dup.push_back({{"index", index}, {"files", list}});
        std::optional<ExperimentConfig> e;
        if (!g.study_config.is_null()) {
          // Re-expanding the stored matrix tells which cells should be there. Results of an older
          // binary may hold a config this one rejects: say so instead of failing the whole index.
          try {
            e = parse_experiment_config(g.study_config, g.source, g.quick, g.study);
          } catch (const ConfigError& err) {
            s["expand_error"] = err.what();
            std::printf("%s: cannot re-expand the stored matrix: %s\n", name.c_str(), err.what());
          }
        }
        // The cells owed: those `run` planned; for results without a plan (an older binary),
        // the re-expanded matrix.
        std::map<int, json> expected = g.planned;
        if (expected.empty() && e)
          for (const Cell& c : e->cells)
            expected[c.index] = {{"repetition", c.repetition}, {"assignment", c.assignment}};
        if (!g.plans.empty()) s["plans"] = g.plans;
        if (!g.planned.empty() || e) {
          s["cells_expected"] = expected.size();
          for (const auto& [index, c] : expected)
            if (!g.files_by_index.count(index)) missing.push_back(index);
        }
        if (e && !g.without_distance.empty()) {
          json lacking = json::array();
          for (int index : g.without_distance)
            if (index >= 0 && index < int(e->cells.size()) &&
                !matches_assignment(e->cells[size_t(index)], e->metrics.reference))
              lacking.push_back(index);
          if (!lacking.empty()) {
            s["without_reference_distance"] = lacking;
            std::printf(
                "%s: %zu cells lack their reference distance (rerun `mcfbench run` without --shard "
                "to add them)\n",
                name.c_str(), lacking.size());
          }
        }
        s["missing"] = missing;
        s["duplicates"] = dup;
        s["errors"] = g.errored;
        // An errored cell is there but holds no result: as incomplete as a missing one.
        problems = problems || !missing.empty() || !dup.empty() || !g.errored.empty();
        std::printf("%s: %zu cells found%s, %zu missing, %zu duplicated, %zu errored\n",
                    name.c_str(), g.files_by_index.size(),
                    s.contains("cells_expected")
                        ? (" of " + std::to_string(s["cells_expected"].get<size_t>())).c_str()
                        : "",
                    missing.size(), dup.size(), g.errored.size());
        if (!missing.empty()) {
          constexpr size_t shown = 5;
          std::string list;
          for (size_t i = 0; i < std::min(shown, missing.size()); ++i)
            list += (i ? ", " : "") +
                    describe_cell(missing[i].get<int>(), expected[missing[i].get<int>()]);
          if (missing.size() > shown)
            list += ", ... and " + std::to_string(missing.size() - shown) + " more";
          std::printf("  missing cells (%zu): %s (rerun `mcfbench run` to compute them)\n",
                      missing.size(), list.c_str());
        }
        if (!g.errored.empty())
          std::printf("  errored cell indices: %s (rerun `mcfbench run` to retry them)\n",
                      json(g.errored).dump().c_str());
        studies.push_back(s);
      }
      const std::string out =
          !a->out.empty() ? a->out : (fs::path(a->dirs.front()) / "index.json").string();
      write_file_atomic(out, json{{"schema", 1},
                                  {"dirs", a->dirs},
                                  {"studies", studies},
                                  {"duplicates", duplicates},
                                  {"unreadable", unreadable},
                                  {"empty_dirs", empty_dirs},
                                  {"files", files}}
                                     .dump(1) +
                                 "\n");
      std::printf("wrote %s (%zu result files)%s\n", out.c_str(), files.size(),
                  problems ? "; INCOMPLETE (missing, errored or unreadable cells, or a folder with "
                             "nothing to collect) or DUPLICATED cells"
                           : "");
      return problems ? 1 : 0;
    };
  });
}

}  // namespace mcf
