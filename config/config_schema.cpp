#include "config/config_schema.h"

#include "config/basis_registry.h"
#include "config/config_reader.h"
#include "config/flow_registry.h"
#include "config/solver_registry.h"
#include "steps/integrator.h"

#include <algorithm>
#include <cstdio>
#include <stdexcept>

namespace mcf {
namespace {

/// The flow's own keys before the components' (mesh, flow, basis, mass).
std::vector<OptionSpec> head_options() {
  OptionSpec mesh = bind(
      option("mesh", OptionType::string, "", "--mesh", "The input surface"),
      [](auto& c) -> auto& { return c.mesh; });
  mesh.default_text = "required";
  mesh.values_text = "a mesh spec: generator, cgal:MODEL[@faces=N] or a file path";
  mesh.after = [](FlowConfig& c, const ConfigReader& r, const std::string& leaf) {
    if (c.mesh.empty()) r.fail(leaf, "missing (a mesh spec such as \"sphere:vertices=2000\")");
  };
  OptionSpec flow = bind(
      option("flow", OptionType::string, "mcf", "--flow", "The flow"),
      [](auto& c) -> auto& { return c.flow; });
  flow.choices = [] { return flow_table().choices(); };
  OptionSpec basis = bind(
      option("basis", OptionType::string, "hat", "--basis", "The finite-element basis"),
      [](auto& c) -> auto& { return c.basis; });
  basis.choices = [] { return basis_table().choices(); };
  OptionSpec mass = bind(
      option("mass", OptionType::string, "consistent", "--mass",
             "Hat basis mass matrix (the octree basis integrates its "
             "consistent mass by cubature and refuses lumped)"),
      [](auto& c) -> auto& { return c.mass; });
  mass.choices = [] {
    return std::vector<Choice>{{"consistent", "the consistent mass matrix"},
                               {"lumped", "the lumped (diagonal) mass matrix"}};
  };
  return {mesh, flow, basis, mass};
}

nlohmann::json blas_threads_of_flag(const std::string& text) {
  if (text == "auto") return 0;
  int n = 0;
  std::size_t used = 0;
  try {
    n = std::stoi(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || n < 1 || n > 4096)
    throw std::invalid_argument("expected auto or a count 1..4096, got \"" + text + "\"");
  return n;
}

/// The flow's own keys after the components' (time stepping, threads, output).
std::vector<OptionSpec> tail_options() {
  OptionSpec integrator = bind(
      option("integrator", OptionType::string, "semi-implicit", "--integrator",
             "Time integrator (docs/design.md)"),
      [](auto& c) -> auto& { return c.integrator; });
  integrator.choices = [] {
    std::vector<Choice> c;
    for (const IntegratorRow& row : integrator_table()) c.emplace_back(row.name, row.help);
    return c;
  };
  OptionSpec extrapolate = bind(
      option("extrapolate", OptionType::boolean, true, "--frozen",
             "CN/BDF2: operators at the extrapolated X*; --frozen "
             "evaluates them at X_n instead (first order)"),
      [](auto& c) -> auto& { return c.extrapolate; });
  extrapolate.flag_kind = FlagKind::set_false;
  extrapolate.refused_elsewhere = true;
  extrapolate.owner_text = "the two-step integrators (";
  for (const IntegratorRow& row : integrator_table())
    if (row.reads_extrapolate)
      extrapolate.owner_text += (extrapolate.owner_text.back() == '(' ? "" : ", ") + row.name;
  extrapolate.owner_text += ")";
  extrapolate.selected = [](const FlowConfig& c) {
    return integrator_reads_extrapolate(c.integrator);
  };
  extrapolate.in_use = [](const FlowConfig& c) {
    return "the integrator is \"" + c.integrator + "\"";
  };
  OptionSpec dt = ranged(bind(
                             option("dt", OptionType::number, 1e-3, "--dt", "Time step"),
                             [](auto& c) -> auto& { return c.dt; }),
                         1e-300, 1e6);
  dt.values_text = "> 0";
  dt.after = [](FlowConfig& c, const ConfigReader& r, const std::string& leaf) {
    if (c.dt <= 0) r.fail(leaf, "must be > 0");
  };
  OptionSpec steps =
      ranged(bind(
                 option("steps", OptionType::integer, 10, "--steps", "Number of steps"),
                 [](auto& c) -> auto& { return c.steps; }),
             0, 100000000);
  OptionSpec normalize = bind(
      option("normalize_area", OptionType::boolean, false, "--normalize-area",
             "Unit total area, centroid at the origin, before and after "
             "every step (refused on an open surface)"),
      [](auto& c) -> auto& { return c.normalize_area; });
  normalize.flag_kind = FlagKind::set_true;
  OptionSpec threads = ranged(bind(
                                  option("threads", OptionType::integer, 0, "--threads",
                                         "Worker threads, and the most OpenBLAS may use under "
                                         "CHOLMOD"),
                                  [](auto& c) -> auto& { return c.threads; }),
                              0, 4096);
  threads.default_text = "0 = all cores";
  OptionSpec ranks = ranged(bind(
                                option("mpi_ranks", OptionType::integer, 1, "--mpi-ranks",
                                       "MPI ranks the solve is spread over: `mcfbench run` "
                                       "starts the cell under mpirun -n N; `mcfbench flow` "
                                       "must be started so (docs/petsc.md)"),
                                [](auto& c) -> auto& { return c.mpi_ranks; }),
                            1, 4096);
  ranks.recorded = Recorded::when_set;
  ranks.refused_elsewhere = true;
  ranks.owner_text =
      "a solver that runs across MPI ranks (petsc, multigrid, pcg with the multigrid "
      "preconditioner)";
  ranks.selected = [](const FlowConfig& c) { return runs_across_ranks(c.solver); };
  OptionSpec blas = ranged(bind(
                               option("blas_threads", OptionType::integer, 0, "--blas-threads",
                                      "OpenBLAS threads under CHOLMOD: auto (one below 20000 "
                                      "unknowns, else up to 4) or a count, at most --threads"),
                               [](auto& c) -> auto& { return c.solver.blas_threads; }),
                           0, 4096);
  blas.default_text = "auto (0 in the config)";
  blas.values_text = "auto | 1..4096";
  blas.parse_flag = blas_threads_of_flag;
  blas.refused_elsewhere = true;
  blas.owner_text = "a solver that factorizes with CHOLMOD (cholmod)";
  blas.selected = [](const FlowConfig& c) { return solver_row(c.solver.name).uses_blas_threads; };
  OptionSpec save = ranged(bind(
                               option("save_every", OptionType::integer, 0, "--save-every",
                                      "Write OUT/frame_NNNNN.ply every K steps"),
                               [](auto& c) -> auto& { return c.save_every; }),
                           0, 100000000);
  save.default_text = "0 = never";
  OptionSpec repair = bind(
      option("repair_degenerate", OptionType::boolean, false, "--repair-degenerate",
             "Collapse the mesh's zero-area faces first (the hat basis "
             "refuses them; the octree basis takes them as they are)"),
      [](auto& c) -> auto& { return c.repair_degenerate; });
  repair.flag_kind = FlagKind::set_true;
  repair.recorded = Recorded::when_set;
  return {integrator, extrapolate, dt, steps, normalize, threads, ranks, blas, save, repair};
}

std::vector<OptionSpec> gather() {
  std::vector<OptionSpec> all = head_options();
  for (const BasisRow& row : basis_table().rows())
    for (OptionSpec o : row.options) {
      // A basis's own options, unless the option says which bases read it.
      if (!o.selected) {
        o.owner = row.name;
        o.owner_text = "basis \"" + row.name + "\"";
        o.selected = [name = row.name](const FlowConfig& c) { return c.basis == name; };
        o.refused_elsewhere = true;
      }
      if (o.refused_elsewhere) {
        if (!o.in_use)
          o.in_use = [](const FlowConfig& c) { return "the basis is \"" + c.basis + "\""; };
        o.matrix_drops = true;
      }
      all.push_back(std::move(o));
    }
  const std::vector<OptionSpec>& shared = solver_options();
  all.insert(all.end(), shared.begin(), shared.end());
  for (const SolverRow& row : solver_table().rows())
    for (OptionSpec o : row.options) {
      o.key = "solver." + o.key;
      o.owner = row.name;
      o.owner_text = "solver \"" + row.name + "\"";
      o.selected = [name = row.name](const FlowConfig& c) { return c.solver.name == name; };
      o.recorded = Recorded::when_selected;
      // Not recorded where its solver does not run, so a value set there would be dropped
      // without a word.
      o.refused_elsewhere = true;
      all.push_back(std::move(o));
    }
  const std::vector<OptionSpec> tail = tail_options();
  all.insert(all.end(), tail.begin(), tail.end());
  return all;
}

std::string number_text(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

}  // namespace

const std::vector<OptionSpec>& flow_config_schema() {
  // Built on first use, after every row registered from a static initializer.
  static const std::vector<OptionSpec> schema = gather();
  return schema;
}

const OptionSpec& option_spec(const std::string& key) {
  for (const OptionSpec& o : flow_config_schema())
    if (o.key == key) return o;
  throw std::out_of_range("no config key \"" + key + "\"");
}

std::string option_values(const OptionSpec& o) {
  if (!o.values_text.empty()) return o.values_text;
  if (o.choices) {
    std::string v;
    for (const Choice& c : o.choices()) v += (v.empty() ? "" : " | ") + c.first;
    return v;
  }
  switch (o.type) {
    case OptionType::integer:
      return number_text(o.min) + ".." + number_text(o.max);
    case OptionType::number:
      return "[" + number_text(o.min) + ", " + number_text(o.max) + "]";
    case OptionType::boolean:
      return "true | false";
    case OptionType::string:
      break;
  }
  return "text";
}

std::string option_default(const OptionSpec& o) {
  if (!o.default_text.empty()) return o.default_text;
  if (o.fallback.is_string()) {
    const std::string s = o.fallback.get<std::string>();
    return s.empty() ? "\"\"" : s;
  }
  if (o.fallback.is_number_float()) return number_text(o.fallback.get<double>());
  return o.fallback.dump();
}

std::string option_flag_help(const OptionSpec& o) {
  std::string h = o.help;
  if (o.flag_kind != FlagKind::value) return h + " (config key " + o.key + ")";
  if (o.choices) {
    h += ":";
    const char* sep = " ";
    for (const Choice& c : o.choices()) {
      h += sep + c.first + (c.second.empty() ? "" : " (" + c.second + ")");
      sep = " | ";
    }
  } else {
    h += ": " + option_values(o);
  }
  return h + "; default " + option_default(o);
}

std::string flow_options_markdown() {
  std::string md = "| flag | config key | values | default | meaning |\n|---|---|---|---|---|\n";
  auto cell = [](std::string s) {
    std::string out;
    for (char ch : s) out += ch == '|' ? std::string("\\|") : std::string(1, ch);
    return out;
  };
  for (const OptionSpec& o : flow_config_schema()) {
    std::string flag = o.flag.empty() ? "" : "`" + o.flag + "`";
    if (o.flag_kind == FlagKind::set_true) flag += " (sets true)";
    if (o.flag_kind == FlagKind::set_false) flag += " (sets false)";
    std::string meaning = o.help;
    if (o.choices)
      for (const Choice& c : o.choices())
        if (!c.second.empty()) meaning += "; `" + c.first + "`: " + c.second;
    if (!o.owner.empty())
      meaning +=
          (o.key.rfind("solver.", 0) == 0 ? " (solver `" : " (basis `") + o.owner + "` only)";
    md += "| " + flag + " | `" + o.key + "` | " + cell(option_values(o)) + " | " +
          cell(option_default(o)) + " | " + cell(meaning) + " |\n";
  }
  return md;
}

const std::vector<std::string>& flow_config_keys() {
  // The schema's keys (config/config_schema.h) and the objects that hold them: every key a cell
  // may set, whether or not result.json records it for the cell's solver.
  static const std::vector<std::string> keys = [] {
    std::vector<std::string> k;
    for (const OptionSpec& o : flow_config_schema()) {
      for (std::size_t dot = o.key.find('.'); dot != std::string::npos;
           dot = o.key.find('.', dot + 1))
        k.push_back(o.key.substr(0, dot));
      k.push_back(o.key);
    }
    std::sort(k.begin(), k.end());
    k.erase(std::unique(k.begin(), k.end()), k.end());
    return k;
  }();
  return keys;
}

}  // namespace mcf
