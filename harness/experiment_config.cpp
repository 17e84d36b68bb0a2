#include "harness/experiment_config.h"

#include "config/config_reader.h"
#include "config/config_schema.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

namespace mcf {
namespace {

using nlohmann::json;

[[noreturn]] void fail(const std::string& source, const std::string& path,
                       const std::string& what) {
  throw ConfigError(source + ": " + path + ": " + what);
}

bool is_config_key(const std::string& k) {
  const auto& keys = flow_config_keys();
  return std::find(keys.begin(), keys.end(), k) != keys.end();
}

std::string known_keys_hint() {
  std::string s = " (known keys:";
  for (const auto& k : flow_config_keys()) s += " " + k;
  return s + ")";
}

void require_config_key(const std::string& source, const std::string& where,
                        const std::string& key) {
  if (!is_config_key(key)) fail(source, where + key, "unknown config key" + known_keys_hint());
}

/// Unknown keys inside a (nested) flow-config object are reported with their full dotted path
/// before any cell is built, so a typo in `defaults` is named as such (not as a cell error).
void check_config_object(const json& j, const std::string& source, const std::string& where,
                         const std::string& prefix = "") {
  if (!j.is_object())
    fail(source, where.empty() ? "config" : where.substr(0, where.size() - 1),
         "expected an object, got " + j.dump());
  for (auto it = j.begin(); it != j.end(); ++it) {
    const std::string key = prefix.empty() ? it.key() : prefix + "." + it.key();
    if (!is_config_key(key)) fail(source, where + key, "unknown key" + known_keys_hint());
    if (it->is_object()) check_config_object(*it, source, where, key);
  }
}

/// `defaults` with its dotted keys ("solver.name": v, as axes, zip and exclude name keys) put in
/// place as nested objects, which the flow config reads; a dotted key is applied after the nested
/// object of the same name, so it wins over it.
json nest_dotted_keys(const json& defaults) {
  json nested = json::object();
  for (auto it = defaults.begin(); it != defaults.end(); ++it)
    if (it.key().find('.') == std::string::npos) nested[it.key()] = *it;
  for (auto it = defaults.begin(); it != defaults.end(); ++it)
    if (it.key().find('.') != std::string::npos) set_json_path(nested, it.key(), *it);
  return nested;
}

/// One dimension of the matrix: several keys that vary together (one key for an axis).
struct Dimension {
  std::vector<std::string> keys;
  std::vector<std::vector<json>> rows;  // rows[i][k] = value of keys[k] in the i-th setting
};

const json& member(const json& j, const char* key) {
  static const json null_value;
  return j.contains(key) ? j.at(key) : null_value;
}

void check_axes(const json& axes, const std::string& source, const std::string& where) {
  if (axes.is_null()) return;
  if (!axes.is_object())
    fail(source, where, "expected an object {dotted key: [values]}, got " + axes.dump());
  for (auto it = axes.begin(); it != axes.end(); ++it) {
    require_config_key(source, where + ".", it.key());
    if (!it->is_array() || it->empty())
      fail(source, where + "." + it.key(),
           "expected a non-empty list of values, got " + it->dump());
  }
}

void check_zip(const json& zip, const std::string& source, const std::string& where) {
  if (zip.is_null()) return;
  if (!zip.is_array())
    fail(source, where,
         "expected a list of groups [{dotted key: [values]}, ...], got " + zip.dump());
  for (size_t g = 0; g < zip.size(); ++g) {
    const std::string gp = where + "[" + std::to_string(g) + "]";
    const json& group = zip[g];
    if (!group.is_object() || group.empty())
      fail(source, gp, "expected a non-empty object {dotted key: [values]}, got " + group.dump());
    std::string first_key;
    size_t length = 0;
    for (auto it = group.begin(); it != group.end(); ++it) {
      require_config_key(source, gp + ".", it.key());
      if (!it->is_array() || it->empty())
        fail(source, gp + "." + it.key(), "expected a non-empty list of values, got " + it->dump());
      if (first_key.empty()) {
        first_key = it.key();
        length = it->size();
      } else if (it->size() != length) {
        fail(source, gp + "." + it.key(),
             std::to_string(it->size()) + " values, but " + gp + "." + first_key + " has " +
                 std::to_string(length) +
                 " (the lists of a zip group vary together and must be equally long)");
      }
    }
  }
}

void check_exclude(const json& exclude, const std::string& source, const std::string& where) {
  if (exclude.is_null()) return;
  if (!exclude.is_array())
    fail(
        source, where,
        "expected a list of partial assignments [{dotted key: value}, ...], got " + exclude.dump());
  for (size_t i = 0; i < exclude.size(); ++i) {
    const std::string ip = where + "[" + std::to_string(i) + "]";
    if (!exclude[i].is_object() || exclude[i].empty())
      fail(source, ip, "expected a non-empty object {dotted key: value}, got " + exclude[i].dump());
    for (auto it = exclude[i].begin(); it != exclude[i].end(); ++it)
      require_config_key(source, ip + ".", it.key());
  }
}

int read_repetitions(const json& r, const std::string& source, const std::string& where) {
  if (r.is_null()) return 1;
  if (!r.is_number_integer() || r.get<long long>() < 1 || r.get<long long>() > 1000000)
    fail(source, where, "expected an integer >= 1, got " + r.dump());
  return r.get<int>();
}

MetricsConfig read_metrics(const json& m, const std::string& source) {
  MetricsConfig out;
  if (m.is_null()) return out;
  ConfigReader r(m, source, "metrics");
  out.quasi_conformal = r.get_bool("quasi_conformal", false);
  out.sphericity = r.get_bool("sphericity", false);
  out.every = int(r.get_integer("every", 1, 1, 100000000));
  out.distance_samples = r.get_integer("distance_samples", out.distance_samples, 100, 100000000);
  // Lists and partial assignments are not ConfigReader types, so the key set is checked here.
  for (auto it = m.begin(); it != m.end(); ++it) {
    const std::string& k = it.key();
    if (k == "quasi_conformal" || k == "sphericity" || k == "every" || k == "distance_samples")
      continue;
    if (k == "frames") {
      if (!it->is_array())
        fail(source, "metrics.frames", "expected a list of step numbers, got " + it->dump());
      for (const auto& s : *it) {
        if (!s.is_number_integer() || s.get<long long>() < 0 || s.get<long long>() > 100000000)
          fail(source, "metrics.frames", "expected step numbers >= 0, got " + s.dump());
        out.frames.push_back(s.get<int>());
      }
      std::sort(out.frames.begin(), out.frames.end());
      out.frames.erase(std::unique(out.frames.begin(), out.frames.end()), out.frames.end());
    } else if (k == "reference") {
      if (!it->is_object() || it->empty())
        fail(source, "metrics.reference",
             "expected a non-empty object {dotted key: value}, got " + it->dump());
      for (auto e = it->begin(); e != it->end(); ++e)
        require_config_key(source, "metrics.reference.", e.key());
      out.reference = *it;
    } else {
      fail(source, "metrics." + k,
           "unknown key (known: quasi_conformal, sphericity, every, frames, reference, "
           "distance_samples)");
    }
  }
  if (!out.reference.is_null() && out.frames.empty())
    fail(source, "metrics.reference",
         "needs metrics.frames: distances are computed between saved frames");
  return out;
}

json default_value(const std::string& key) {
  static const json defaults = to_json(FlowConfig{});
  const json* v = json_at_path(defaults, key);
  return v ? *v : json();
}

/// Exclusion is decided before validation, on the raw config plus the defaults, because
/// excluding invalid combinations (say hat + multigrid) is exactly what `exclude` is for.
/// Whether `raw` matches an entry of `exclude`; `used[i]` is set for every entry i it matches.
bool excluded(const json& raw, const json& exclude, std::vector<bool>& used) {
  if (!exclude.is_array()) return false;
  bool any = false;
  for (size_t i = 0; i < exclude.size(); ++i) {
    bool all = true;
    for (auto it = exclude[i].begin(); it != exclude[i].end() && all; ++it) {
      const json* v = json_at_path(raw, it.key());
      all = (v ? *v : default_value(it.key())) == *it;
    }
    if (all) used[i] = any = true;
  }
  return any;
}

}  // namespace

namespace {

/// Whether `value` is the default of an option that result.json's config records only when set
/// or only for some components (mpi_ranks 1, repair_degenerate false): its absence from a cell's
/// config means that value.
bool is_unrecorded_default(const std::string& key, const json& value) {
  for (const OptionSpec& o : flow_config_schema())
    if (o.key == key) return o.recorded != Recorded::always && o.fallback == value;
  return false;
}

}  // namespace

bool matches_assignment(const Cell& cell, const json& partial) {
  if (!partial.is_object()) return false;
  for (auto it = partial.begin(); it != partial.end(); ++it) {
    const json* v = json_at_path(cell.config, it.key());
    if (v ? *v != *it : !is_unrecorded_default(it.key(), *it)) return false;
  }
  return true;
}

namespace {

/// The top level's keys, name and description.
void read_header(const json& j, const std::string& source, ExperimentConfig& e) {
  static const std::set<std::string> top = {
      "name",    "description", "paper",      "comment",    "defaults", "axes", "zip",
      "exclude", "repetitions", "interleave", "order_seed", "metrics",  "quick"};
  for (auto it = j.begin(); it != j.end(); ++it)
    if (!top.count(it.key()))
      fail(source, it.key(),
           "unknown key (known: name, description, paper, comment, defaults, axes, zip, exclude, "
           "repetitions, interleave, order_seed, metrics, quick)");
  if (j.contains("name")) {
    if (!j["name"].is_string() || j["name"].get<std::string>().empty())
      fail(source, "name", "expected a non-empty string, got " + j["name"].dump());
    e.name = j["name"].get<std::string>();
    if (e.name.find('/') != std::string::npos)
      fail(source, "name", "must not contain '/' (it names the results folder)");
  }
  if (j.contains("description")) {
    if (!j["description"].is_string())
      fail(source, "description", "expected a string, got " + j["description"].dump());
    e.description = j["description"].get<std::string>();
  }
  if (j.contains("interleave")) {
    if (!j["interleave"].is_boolean())
      fail(source, "interleave", "expected true or false, got " + j["interleave"].dump());
    e.interleave = j["interleave"].get<bool>();
  }
  if (j.contains("order_seed")) {
    const json& s = j["order_seed"];
    if (!s.is_number_integer() || s.get<long long>() < 0)
      fail(source, "order_seed", "expected an integer >= 0, got " + s.dump());
    e.order_seed = s.get<long long>();
  }
}

/// The matrix of the variant being expanded: defaults (dotted keys nested), axes, zip, exclude.
struct MatrixSpec {
  json defaults, axes, zip, exclude;
};

/// Checks the "quick" section's structure; when the quick variant is expanded, merges it into
/// the matrix and `e`: defaults deep, axes per key (a quick axis replaces the full one); zip,
/// exclude, repetitions and metrics (smaller frame lists and sample counts) as a whole.
void apply_quick(const json& q, const std::string& source, bool quick, MatrixSpec& m,
                 ExperimentConfig& e) {
  if (!q.is_object()) fail(source, "quick", "expected an object, got " + q.dump());
  for (auto it = q.begin(); it != q.end(); ++it)
    if (it.key() != "defaults" && it.key() != "axes" && it.key() != "zip" &&
        it.key() != "exclude" && it.key() != "repetitions" && it.key() != "metrics")
      fail(source, "quick." + it.key(),
           "unknown key (known: defaults, axes, zip, exclude, repetitions, metrics)");
  if (q.contains("defaults")) check_config_object(q["defaults"], source, "quick.defaults.");
  check_axes(member(q, "axes"), source, "quick.axes");
  check_zip(member(q, "zip"), source, "quick.zip");
  check_exclude(member(q, "exclude"), source, "quick.exclude");
  const int quick_reps = read_repetitions(member(q, "repetitions"), source, "quick.repetitions");
  const bool quick_metrics = q.contains("metrics");
  const MetricsConfig quick_metric_config =
      quick_metrics ? read_metrics(q["metrics"], source) : MetricsConfig{};
  if (!quick) return;
  if (quick_metrics) e.metrics = quick_metric_config;
  if (q.contains("defaults")) m.defaults.merge_patch(nest_dotted_keys(q["defaults"]));
  if (q.contains("axes")) {
    if (m.axes.is_null()) m.axes = json::object();
    for (auto it = q["axes"].begin(); it != q["axes"].end(); ++it) m.axes[it.key()] = *it;
  }
  if (q.contains("zip")) m.zip = q["zip"];
  if (q.contains("exclude")) m.exclude = q["exclude"];
  if (q.contains("repetitions")) e.repetitions = quick_reps;
}

/// The matrix, repetitions and metrics. The structure of both variants is checked whichever is
/// run, so a broken quick section is found by the full run (and vice versa) rather than months
/// later.
MatrixSpec read_matrix(const json& j, const std::string& source, bool quick, ExperimentConfig& e) {
  MatrixSpec m;
  m.defaults = member(j, "defaults");
  if (m.defaults.is_null()) m.defaults = json::object();
  check_config_object(m.defaults, source, "defaults.");
  m.defaults = nest_dotted_keys(m.defaults);
  check_axes(member(j, "axes"), source, "axes");
  check_zip(member(j, "zip"), source, "zip");
  check_exclude(member(j, "exclude"), source, "exclude");
  e.repetitions = read_repetitions(member(j, "repetitions"), source, "repetitions");
  e.metrics = read_metrics(member(j, "metrics"), source);
  m.axes = member(j, "axes");
  m.zip = member(j, "zip");
  m.exclude = member(j, "exclude");
  if (const json& q = member(j, "quick"); !q.is_null()) apply_quick(q, source, quick, m, e);
  return m;
}

/// One dimension per axis (keys sorted, as nlohmann keeps them) and per zip group; a key may
/// vary in one of them only, and no varied key may contain another.
std::vector<Dimension> dimensions(const MatrixSpec& m, const std::string& source,
                                  const std::string& axes_where) {
  std::vector<Dimension> dims;
  std::set<std::string> varied;
  if (m.axes.is_object())
    for (auto it = m.axes.begin(); it != m.axes.end(); ++it) {
      Dimension d;
      d.keys = {it.key()};
      for (const auto& v : *it) d.rows.push_back({v});
      varied.insert(it.key());
      dims.push_back(std::move(d));
    }
  if (m.zip.is_array())
    for (size_t g = 0; g < m.zip.size(); ++g) {
      Dimension d;
      size_t length = 0;
      for (auto it = m.zip[g].begin(); it != m.zip[g].end(); ++it) {
        if (!varied.insert(it.key()).second)
          fail(source, "zip[" + std::to_string(g) + "]." + it.key(),
               "key varies twice (also in axes or another zip group)");
        d.keys.push_back(it.key());
        length = it->size();
      }
      for (size_t i = 0; i < length; ++i) {
        std::vector<json> row;
        for (const auto& k : d.keys) row.push_back(m.zip[g][k][i]);
        d.rows.push_back(std::move(row));
      }
      dims.push_back(std::move(d));
    }
  for (const auto& k : varied)
    for (const auto& other : varied)
      if (k != other && other.rfind(k + ".", 0) == 0)
        fail(source, axes_where,
             "keys \"" + k + "\" and \"" + other + "\" overlap (one contains the other)");
  return dims;
}

// The most cells a matrix may expand into, repetitions included: far beyond any study that could
// run, and small enough to expand in seconds. A few lines of axes (or "repetitions": 1000000)
// would otherwise multiply into billions of cells and exhaust the memory while expanding.
constexpr double kMaxCells = 100'000;

/// Refuses a matrix of more than kMaxCells cells before any is built (counted before excludes).
void check_matrix_size(const std::vector<Dimension>& dims, int repetitions,
                       const std::string& source, const std::string& axes_where) {
  double cells = repetitions;
  std::string product;
  for (const Dimension& d : dims) {
    cells *= static_cast<double>(d.rows.size());
    product += std::to_string(d.rows.size()) + " x ";
  }
  if (cells > kMaxCells)
    fail(source, axes_where,
         "the matrix has " + product + std::to_string(repetitions) +
             " repetitions = " + std::to_string(static_cast<long long>(std::min(cells, 1e18))) +
             " cells, more than the " + std::to_string(static_cast<long long>(kMaxCells)) +
             " an experiment may have");
}

/// The cells: an odometer over the dimensions, the last one fastest, each assignment applied
/// to the defaults, every repetition of a cell no exclude entry matches (`exclude_used` marks
/// the entries that matched one).
void expand_cells(const std::vector<Dimension>& dims, const MatrixSpec& m,
                  const std::string& source, ExperimentConfig& e, std::vector<bool>& exclude_used) {
  std::vector<size_t> pos(dims.size(), 0);
  int index = 0;
  bool done = false;
  while (!done) {
    json raw = m.defaults, assignment = json::object();
    for (size_t d = 0; d < dims.size(); ++d)
      for (size_t k = 0; k < dims[d].keys.size(); ++k) {
        // null: this row leaves the key as the defaults have it (a zip's column that the row's
        // components do not read, e.g. the multigrid's stall_ratio on a CHOLMOD row).
        const json& value = dims[d].rows[pos[d]][k];
        if (value.is_null()) continue;
        set_json_path(raw, dims[d].keys[k], value);
        assignment[dims[d].keys[k]] = value;
      }
    if (!excluded(raw, m.exclude, exclude_used)) {
      const std::string where = assignment.empty() ? source + " (defaults)"
                                                   : source + " (cell " + assignment.dump() + ")";
      // A default applies to the cells whose components read it (defaults {"solver.cycles": 2}
      // beside an axis of solvers sets the multigrid's cycles, not CHOLMOD's), and so does a
      // basis's option from any part of the matrix (octree.depth tied to the mesh sets the octree
      // cells' depth, not the hat cells'); any other value the cell's own assignment gives is
      // checked strictly.
      FlowConfig flow = flow_config_from_json_unchecked(raw, where);
      bool dropped = false;
      for (const std::string& key : inapplicable_keys(flow))
        if (!assignment.contains(key) || option_spec(key).matrix_drops) {
          erase_json_path(raw, key);
          assignment.erase(key);
          dropped = true;
        }
      if (dropped) flow = flow_config_from_json_unchecked(raw, where);
      validate_flow_config(flow, where);
      for (int r = 0; r < e.repetitions; ++r) {
        Cell c;
        c.index = index++;
        c.repetition = r;
        c.assignment = assignment;
        c.flow = flow;
        c.config = to_json(flow);
        e.cells.push_back(std::move(c));
      }
    }
    done = true;
    for (size_t d = dims.size(); d-- > 0;) {
      if (++pos[d] < dims[d].rows.size()) {
        done = false;
        break;
      }
      pos[d] = 0;
    }
  }
}

/// Mistakes only the expanded matrix shows: every cell excluded, an exclude entry or a frame no
/// cell meets, two cells with one flow config, a reference no cell matches. `own_exclude` and
/// `own_frames`: whether the variant expanded has its own exclude list and frame list (the full
/// config's, applied to quick.axes, may rightly match nothing or stop short of them).
void check_cells(const ExperimentConfig& e, const MatrixSpec& m, const std::string& source,
                 const std::string& axes_where, const std::vector<bool>& exclude_used,
                 bool own_exclude, bool own_frames) {
  if (e.cells.empty()) fail(source, "exclude", "every cell of the matrix is excluded");
  // An entry that excludes nothing is a typo ("hta") or a value no axis has.
  for (size_t i = 0; own_exclude && i < exclude_used.size(); ++i)
    if (!exclude_used[i])
      fail(source,
           std::string(e.quick ? "quick.exclude" : "exclude") + "[" + std::to_string(i) + "]",
           "matches no cell of the matrix: " + m.exclude[i].dump());
  // A frame no cell reaches would silently save nothing (and give no reference distance).
  int max_steps = 0;
  for (const Cell& c : e.cells) max_steps = std::max(max_steps, c.flow.steps);
  for (int f : e.metrics.frames)
    if (own_frames && f > max_steps)
      fail(source, e.quick ? "quick.metrics.frames" : "metrics.frames",
           "step " + std::to_string(f) + " is beyond every cell's steps (at most " +
               std::to_string(max_steps) + ")");
  // Two cells with the same full config would share one result file (same key): the second
  // would be "skipped" and `collect` would report it missing. Usually a duplicated axis value.
  std::map<std::string, const Cell*> seen;
  for (const Cell& c : e.cells) {
    auto [it, fresh] = seen.emplace(c.config.dump() + "#" + std::to_string(c.repetition), &c);
    if (!fresh)
      fail(source, axes_where,
           "cells " + it->second->assignment.dump() + " and " + c.assignment.dump() +
               " are the same flow config (duplicate values?)");
  }
  if (!e.metrics.reference.is_null() &&
      std::none_of(e.cells.begin(), e.cells.end(),
                   [&](const Cell& c) { return matches_assignment(c, e.metrics.reference); }))
    fail(source, "metrics.reference",
         "matches no cell of the matrix: " + e.metrics.reference.dump());
}

}  // namespace

ExperimentConfig parse_experiment_config(const json& j, const std::string& source, bool quick,
                                         const std::string& default_name) {
  if (!j.is_object()) throw ConfigError(source + ": expected a JSON object at the top level");
  ExperimentConfig e;
  e.source = source;
  e.quick = quick;
  e.study_config = j;
  e.name = default_name;
  read_header(j, source, e);
  const MatrixSpec m = read_matrix(j, source, quick, e);
  const std::string axes_where = quick ? "axes (with quick.axes)" : "axes";
  const std::vector<Dimension> dims = dimensions(m, source, axes_where);
  check_matrix_size(dims, e.repetitions, source, axes_where);
  std::vector<bool> exclude_used(m.exclude.is_array() ? m.exclude.size() : 0, false);
  expand_cells(dims, m, source, e, exclude_used);
  const json& q = member(j, "quick");
  const bool own_exclude = !quick || (q.is_object() && q.contains("exclude"));
  const bool own_frames = !quick || (q.is_object() && q.contains("metrics"));
  check_cells(e, m, source, axes_where, exclude_used, own_exclude, own_frames);
  return e;
}

ExperimentConfig load_experiment_config(const std::string& path, bool quick) {
  const json j = read_config_file(path);
  // Without a "quick" section --quick would run the full matrix and label it quick.
  if (quick && !(j.is_object() && j.contains("quick")))
    throw ConfigError(
        path + ": --quick: the config has no \"quick\" section (add one, or run without --quick)");
  return parse_experiment_config(j, path, quick, std::filesystem::path(path).stem().string());
}

}  // namespace mcf
