// run() is `mcfbench run` (harness/run_with_progress.h) called in this process; results() reads a
// results folder's cell files into one table.

#include "mcfbench/study.h"

#include "api/detail.h"

#include "config/config_reader.h"
#include "harness/run_with_progress.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <tuple>

namespace mcfbench {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

/// Left out of the table: per-step records, the study's whole config, the frames written, the
/// library versions and the config (whose keys are columns of their own, without the prefix).
bool left_out(const std::string& path) {
  for (const char* p : {"steps", "study_config", "frames", "config", "environment.libraries",
                        "memory_budget.source"})
    if (path == p) return true;
  return false;
}

/// Every scalar leaf of `j` under `prefix`, by dotted path (arrays are left out).
/// `filter`: skip what left_out() names.
void leaves(const json& j, const std::string& prefix, std::map<std::string, Value>& out,
            bool filter) {
  if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it) {
      const std::string path = prefix.empty() ? it.key() : prefix + "." + it.key();
      if (!filter || !left_out(path)) leaves(it.value(), path, out, filter);
    }
  } else if (j.is_boolean()) {
    out.emplace(prefix, j.get<bool>());
  } else if (j.is_number_integer()) {
    out.emplace(prefix, j.get<long long>());
  } else if (j.is_number()) {
    out.emplace(prefix, j.get<double>());
  } else if (j.is_string()) {
    out.emplace(prefix, j.get<std::string>());
  }
}

}  // namespace

int run(const std::string& config, const RunOptions& options) {
  if (options.out.empty())
    throw InputError("run: " + config + ": the results folder (out) is required");
  const detail::RunScope one_at_a_time("run: " + config);
  mcf::RunRequest request;
  request.config = config;
  request.out = options.out;
  request.shard = options.shard;
  request.force = options.force;
  request.quick = options.quick;
  request.threads = options.threads;
  request.max_memory = options.max_memory;
  return detail::translated([&] { return mcf::run_experiment_with_progress(request); });
}

ResultsTable results(const std::string& folder) {
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) throw InputError("results: " + folder + ": no such folder");
  struct Row {
    long long index = 0, repetition = 0;
    std::map<std::string, Value> config, rest;
  };
  std::vector<Row> rows;
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(folder, ec))
    if (entry.is_regular_file() && entry.path().extension() == ".json")
      files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  for (const fs::path& file : files) {
    json j;
    try {
      j = mcf::read_config_file(file.string());
    } catch (const std::exception& e) {
      throw InputError(std::string("results: ") + e.what());
    }
    // A cell's result file; the index and other files (collect's) have no "cell".
    if (!j.is_object() || !j.contains("cell") || !j["cell"].is_object()) continue;
    Row row;
    row.index = j["cell"].value("index", 0LL);
    row.repetition = j["cell"].value("repetition", 0LL);
    if (j.contains("config")) leaves(j["config"], "", row.config, false);
    leaves(j, "", row.rest, true);
    rows.push_back(std::move(row));
  }
  std::stable_sort(rows.begin(), rows.end(), [](const Row& a, const Row& b) {
    return std::tie(a.index, a.repetition) < std::tie(b.index, b.repetition);
  });
  // Columns: the config's keys, the cell's, then the rest, each group sorted.
  std::set<std::string> config_set, rest_set;
  for (const Row& r : rows)
    for (const auto& kv : r.config) config_set.insert(kv.first);
  for (const Row& r : rows)
    for (const auto& kv : r.rest)
      if (!config_set.count(kv.first)) rest_set.insert(kv.first);
  std::vector<std::string> config_keys(config_set.begin(), config_set.end()), cell_keys, other_keys;
  for (const std::string& k : rest_set)
    (k.rfind("cell.", 0) == 0 ? cell_keys : other_keys).push_back(k);
  ResultsTable table;
  for (auto* keys : {&config_keys, &cell_keys, &other_keys})
    table.columns.insert(table.columns.end(), keys->begin(), keys->end());
  const std::size_t n_config = config_keys.size();
  for (const Row& r : rows) {
    std::vector<std::optional<Value>> values;
    for (std::size_t c = 0; c < table.columns.size(); ++c) {
      const std::map<std::string, Value>& from = c < n_config ? r.config : r.rest;
      const auto it = from.find(table.columns[c]);
      values.push_back(it == from.end() ? std::nullopt : std::optional<Value>(it->second));
    }
    table.rows.push_back(std::move(values));
  }
  return table;
}

}  // namespace mcfbench
