#include "harness/collect.h"

#include "config/config_reader.h"
#include "core/atomic_file.h"
#include "harness/experiment_config.h"
#include "harness/runner.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <stdexcept>

namespace mcf {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

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

/// A plan's temporary file (`NAME.json.tmp.HOST.PID`, see write_file_atomic) in `plans`, if any.
std::optional<fs::path> temporary_plan(const fs::path& plans) {
  if (!fs::is_directory(plans)) return std::nullopt;
  for (const auto& entry : fs::directory_iterator(plans))
    if (entry.path().filename().string().find(".json.tmp.") != std::string::npos)
      return entry.path();
  return std::nullopt;
}

/// "#3 {"dt":0.001} rep 1 (ab12cd34ef56.json)": a cell named as a user can find it.
std::string describe_cell(int index, const json& c) {
  // Appended piece by piece: GCC 12 warns (-Wrestrict, falsely) on "literal" + std::string here.
  std::string s = "#";
  s += std::to_string(index);
  if (c.contains("assignment") && !c["assignment"].empty())
    s.append(" ").append(c["assignment"].dump());
  if (c.value("repetition", 0) != 0)
    s.append(" rep ").append(std::to_string(c.value("repetition", 0)));
  if (c.contains("hash")) s.append(" (").append(c["hash"].get<std::string>()).append(".json)");
  return s;
}

/// Adds one plan `run` wrote to its study: the cells owed even if none finished.
void add_plan(const fs::path& path, const json& p, ResultFolders& folders) {
  const bool quick = p.value("quick", false);
  StudyResults& g =
      folders.studies[group_name(p.value("study", ""), quick, p.value("commit", "unknown"))];
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

/// The plans of DIR/plans/; returns how many files were plans or unreadable.
std::size_t read_plans(const fs::path& dir, ResultFolders& folders) {
  std::size_t found = 0;
  for (const auto& path : json_files(dir / kPlanFolder)) {
    const std::optional<json> read =
        read_or_list(path, folders.unreadable, "rerun `mcfbench run` to rewrite it");
    if (!read) {
      ++found;
      continue;
    }
    const json& p = *read;
    if (!p.is_object() || !p.contains("cells") || !p["cells"].is_array()) continue;
    ++found;
    add_plan(path, p, folders);
  }
  return found;
}

/// The index entry of one cell result.
json file_entry(const fs::path& path, const json& r, const std::string& commit) {
  const json& c = r["cell"];
  json entry = {{"file", path.string()},
                {"hash", c.value("hash", path.stem().string())},
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
  return entry;
}

/// Adds one cell result to the index and to its study.
void add_result(const fs::path& path, const json& r, ResultFolders& folders) {
  const json& c = r["cell"];
  const std::string commit =
      r.contains("environment") ? r["environment"].value("commit", "unknown") : "unknown";
  const std::string hash = c.value("hash", path.stem().string());
  const json entry = file_entry(path, r, commit);
  folders.files.push_back(entry);
  // The same hash in two folders is the same cell computed twice (overlapping shards).
  if (!folders.seen_hashes.insert(hash).second)
    folders.duplicates.push_back({{"hash", hash}, {"file", path.string()}});
  StudyResults& g = folders.studies[group_name(entry["study"], entry["quick"], commit)];
  if (g.study_config.is_null() && r.contains("study_config")) {
    g.study_config = r["study_config"];
    g.source = path.string() + " (study_config)";
  }
  g.study = entry["study"];
  g.commit = commit;
  g.quick = entry["quick"];
  g.files_by_index[entry["index"].get<int>()].push_back(path.string());
  if (entry["status"] == "error") g.errored.push_back(entry["index"].get<int>());
  // Cells of a study with a reference flow that still lack their distances (their reference
  // was not finished when they ran; an unsharded rerun fills them in).
  if (r.contains("study_config") && r["study_config"].contains("metrics") &&
      r["study_config"]["metrics"].contains("reference") && !r.contains("reference_distance") &&
      !r.contains("reference_cell") && r.value("status", "") != "error")
    g.without_distance.push_back(c.value("index", -1));
}

/// The cell results directly in DIR; returns how many files were results or unreadable.
std::size_t read_results(const fs::path& dir, ResultFolders& folders) {
  std::size_t found = 0;
  for (const auto& path : json_files(dir)) {
    const std::optional<json> read =
        read_or_list(path, folders.unreadable, "rerun `mcfbench run` to redo its cell");
    if (!read) {
      ++found;
      continue;
    }
    const json& r = *read;
    if (!r.is_object() || !r.contains("cell")) continue;
    ++found;
    add_result(path, r, folders);
  }
  return found;
}

/// A mistyped shard folder, or a run killed before it planned anything: nothing here says which
/// cells were meant, so nothing here can vouch that they are all there. A plan's temporary file
/// alone means the run was stopped while publishing its plan.
void note_empty_folder(const std::string& dir, ResultFolders& folders) {
  folders.empty_dirs.push_back(dir);
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

/// The study's matrix re-expanded from the config stored with it: results of an older binary
/// may hold a config this one rejects, which is noted in the entry `s` instead of failing the
/// whole index.
std::optional<ExperimentConfig> reexpand(const std::string& name, const StudyResults& g, json& s) {
  if (g.study_config.is_null()) return std::nullopt;
  try {
    return parse_experiment_config(g.study_config, g.source, g.quick, g.study);
  } catch (const ConfigError& err) {
    s["expand_error"] = err.what();
    std::printf("%s: cannot re-expand the stored matrix: %s\n", name.c_str(), err.what());
    return std::nullopt;
  }
}

/// Cells lacking their reference distance that are not reference cells themselves.
void note_lacking_distances(const std::string& name, const StudyResults& g,
                            const ExperimentConfig& e, json& s) {
  json lacking = json::array();
  for (int index : g.without_distance)
    if (index >= 0 && index < int(e.cells.size()) &&
        !matches_assignment(e.cells[size_t(index)], e.metrics.reference))
      lacking.push_back(index);
  if (lacking.empty()) return;
  s["without_reference_distance"] = lacking;
  std::printf(
      "%s: %zu cells lack their reference distance (`mcfbench run CONFIG --distances-only` "
      "adds them)\n",
      name.c_str(), lacking.size());
}

/// The summary lines of one study on stdout.
void print_study(const std::string& name, const StudyResults& g, const json& s, const json& missing,
                 const json& dup, std::map<int, json>& expected) {
  std::printf("%s: %zu cells found%s, %zu missing, %zu duplicated, %zu errored\n", name.c_str(),
              g.files_by_index.size(),
              s.contains("cells_expected")
                  ? (" of " + std::to_string(s["cells_expected"].get<size_t>())).c_str()
                  : "",
              missing.size(), dup.size(), g.errored.size());
  if (!missing.empty()) {
    constexpr size_t shown = 5;
    std::string list;
    for (size_t i = 0; i < std::min(shown, missing.size()); ++i)
      list +=
          (i ? ", " : "") + describe_cell(missing[i].get<int>(), expected[missing[i].get<int>()]);
    if (missing.size() > shown)
      list += ", ... and " + std::to_string(missing.size() - shown) + " more";
    std::printf("  missing cells (%zu): %s (rerun `mcfbench run` to compute them)\n",
                missing.size(), list.c_str());
  }
  if (!g.errored.empty())
    std::printf("  errored cell indices: %s (rerun `mcfbench run` to retry them)\n",
                json(g.errored).dump().c_str());
}

/// Reads the plans and cell results of every folder (throws std::runtime_error for a path that
/// is not a folder). Unreadable files and folders with nothing to collect are listed in the
/// answer and named on stdout with what to do.
ResultFolders read_result_folders(const std::vector<std::string>& dirs) {
  ResultFolders folders;
  for (const auto& dir : dirs) {
    if (!fs::is_directory(dir)) throw std::runtime_error(dir + ": not a folder");
    // Plans, cell results and unreadable files in this folder (plans first: their notes are
    // printed in this order).
    std::size_t found = read_plans(dir, folders);
    found += read_results(dir, folders);
    if (found == 0) note_empty_folder(dir, folders);
  }
  return folders;
}

/// The index entry of one study: cells found, expected, missing, duplicated, errored, lacking
/// their reference distance; prints its summary lines on stdout. `complete` is cleared when a
/// cell is missing, duplicated or errored.
json check_study(const std::string& name, const StudyResults& g, bool& complete) {
  json s = {{"study", g.study},
            {"quick", g.quick},
            {"commit", g.commit},
            {"cells_found", g.files_by_index.size()}};
  json missing = json::array(), dup = json::array();
  for (const auto& [index, list] : g.files_by_index)
    if (list.size() > 1) dup.push_back({{"index", index}, {"files", list}});
  const std::optional<ExperimentConfig> e = reexpand(name, g, s);
  // The cells owed: those `run` planned; for results without a plan (an older binary), the
  // re-expanded matrix.
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
  if (e && !g.without_distance.empty()) note_lacking_distances(name, g, *e, s);
  s["missing"] = missing;
  s["duplicates"] = dup;
  s["errors"] = g.errored;
  // An errored cell is there but holds no result: as incomplete as a missing one.
  if (!missing.empty() || !dup.empty() || !g.errored.empty()) complete = false;
  print_study(name, g, s, missing, dup, expected);
  return s;
}

}  // namespace

int collect_results(const std::vector<std::string>& dirs, const std::string& index_file) {
  const ResultFolders folders = read_result_folders(dirs);
  json studies = json::array();
  bool complete =
      folders.duplicates.empty() && folders.unreadable.empty() && folders.empty_dirs.empty();
  for (const auto& [name, g] : folders.studies) studies.push_back(check_study(name, g, complete));
  const std::string out =
      !index_file.empty() ? index_file : (fs::path(dirs.front()) / "index.json").string();
  write_file_atomic(out, json{{"schema", 1},
                              {"dirs", dirs},
                              {"studies", studies},
                              {"duplicates", folders.duplicates},
                              {"unreadable", folders.unreadable},
                              {"empty_dirs", folders.empty_dirs},
                              {"files", folders.files}}
                                 .dump(1) +
                             "\n");
  std::printf("wrote %s (%zu result files)%s\n", out.c_str(), folders.files.size(),
              complete ? ""
                       : "; INCOMPLETE (missing, errored or unreadable cells, or a folder with "
                         "nothing to collect) or DUPLICATED cells");
  return complete ? 0 : 1;
}

}  // namespace mcf
