// The Python module `mcfbench` (docs/python.md): a thin layer over the public C++ API
// (include/mcfbench/). Arrays cross as numpy arrays, sparse matrices as scipy.sparse, options as
// keyword arguments that the flow config's schema checks, result records as the dicts result.json
// holds. Flows and studies run with the GIL released; the Python code they call (a step callback,
// a registered solver) takes it for the call, on the thread that runs the flow. A Python exception
// raised there ends the flow and is raised again, unchanged, to the caller; KeyboardInterrupt
// (Ctrl-C) ends a flow after its running step.

#include "convert.h"

#include <pybind11/stl.h>

#include <cstdio>
#include <memory>

namespace py = pybind11;
using namespace pybind11::literals;

namespace mcfbench::python {
namespace {

/// What flow() returns.
struct FlowOutput {
  py::array_t<double> V;
  py::array_t<long long> F;
  py::dict frames;
  py::object result;
};

/// The mesh of a call: arrays V, F or a spec (given as mesh=... among the options).
std::optional<Mesh> mesh_from(py::handle V, py::handle F, const Options& options) {
  if (V.is_none() && F.is_none()) return std::nullopt;
  if (V.is_none() || F.is_none())
    throw py::value_error(options.name + ": give both V and F (or a mesh spec as mesh=...)");
  const Vertices vertices = vertices_from(V);
  const Faces faces = faces_from(F);
  py::gil_scoped_release nogil;
  return Mesh::from_arrays(vertices, faces, options);
}

/// The per-step hook: checks for Ctrl-C (KeyboardInterrupt is raised through the flow) and calls
/// the user's callback(step, t, V); a true return ends the flow.
StepCallback step_hook(py::object callback) {
  auto holder = std::shared_ptr<py::object>(new py::object(std::move(callback)), [](py::object* p) {
    py::gil_scoped_acquire gil;
    delete p;
  });
  return [holder](const Step& s) {
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    if (holder->is_none()) return false;
    const py::object stop = (*holder)(s.step, s.t, to_numpy(s.vertices));
    return !stop.is_none() && stop.cast<bool>();
  };
}

FlowOutput flow(py::handle V, py::handle F, py::object callback, py::handle config,
                py::handle max_memory, bool progress, const py::kwargs& options) {
  Options o = options_from(options, config, max_memory, "mcfbench.flow");
  o.progress = progress;
  if (!callback.is_none() && !PyCallable_Check(callback.ptr()))
    throw py::type_error("mcfbench.flow: callback: expected a function callback(step, t, V)");
  const std::optional<Mesh> mesh = mesh_from(V, F, o);
  const StepCallback hook = step_hook(std::move(callback));
  FlowResult r;
  {
    py::gil_scoped_release nogil;
    r = mesh ? mcfbench::flow(*mesh, o, hook) : mcfbench::flow(o, hook);
  }
  FlowOutput out{to_numpy(r.vertices), to_numpy(r.faces), py::dict(), from_json(r.result_json)};
  for (const Frame& f : r.frames) out.frames[py::int_(f.step)] = to_numpy(f.vertices);
  return out;
}

py::tuple matrices(py::handle V, py::handle F, py::handle config, const py::kwargs& options) {
  const Options o = options_from(options, config, py::none(), "mcfbench.matrices");
  std::optional<Mesh> mesh = mesh_from(V, F, o);
  Operators ops;
  {
    py::gil_scoped_release nogil;
    if (!mesh) {
      // The spec from mesh=...: loaded as Mesh::load does, with the other options.
      Options rest = o;
      std::string spec;
      std::erase_if(rest.settings, [&](const auto& s) {
        if (s.first != "mesh") return false;
        if (const auto* text = std::get_if<std::string>(&s.second.value)) spec = *text;
        return true;
      });
      if (spec.empty())
        throw InputError("mcfbench.matrices: give V and F, or a mesh spec as mesh=...");
      mesh = Mesh::load(spec, rest);
      ops = mcfbench::matrices(*mesh, rest);
    } else {
      ops = mcfbench::matrices(*mesh, o);
    }
  }
  return py::make_tuple(to_python(ops.M), to_python(ops.K));
}

py::tuple load_mesh(const std::string& spec, py::handle config, const py::kwargs& options) {
  const Options o = options_from(options, config, py::none(), "mcfbench.load_mesh");
  std::optional<Mesh> mesh;
  {
    py::gil_scoped_release nogil;
    mesh = Mesh::load(spec, o);
  }
  return py::make_tuple(to_numpy(mesh->vertices()), to_numpy(mesh->faces()));
}

py::object mesh_info(py::handle V, py::handle F, py::handle config, const py::kwargs& options) {
  Options o = options_from(options, config, py::none(), "mcfbench.mesh_info");
  std::optional<Mesh> mesh = mesh_from(V, F, o);
  std::string report;
  {
    py::gil_scoped_release nogil;
    if (!mesh) {
      std::string spec;
      std::erase_if(o.settings, [&](const auto& s) {
        if (s.first != "mesh") return false;
        if (const auto* text = std::get_if<std::string>(&s.second.value)) spec = *text;
        return true;
      });
      if (spec.empty())
        throw InputError("mcfbench.mesh_info: give V and F, or a mesh spec as mesh=...");
      mesh = Mesh::load(spec, o);
    }
    report = mesh->report_json();
  }
  return from_json(report);
}

/// Registered solvers' factories, by name: module attribute _solver_factories, so that the
/// Python objects live and die with the module, not with the library's static table.
py::dict factories() {
  return py::module_::import("mcfbench").attr("_solver_factories");
}

void register_solver(const std::string& name, py::object factory, bool iterative,
                     const std::string& help) {
  if (!PyCallable_Check(factory.ptr()))
    throw py::type_error("mcfbench.register_solver: " + name +
                         ": factory: expected a function factory(A) returning solve(B)");
  SolverDefinition d;
  d.name = name;
  d.help = help;
  d.iterative = iterative;
  d.factory = [name, iterative](const SparseMatrix& A) -> SolveFunction {
    py::gil_scoped_acquire gil;
    const py::object solve = factories()[py::str(name)](to_python(A));
    if (!PyCallable_Check(solve.ptr()))
      throw py::type_error("solver " + name + ": the factory returned " +
                           std::string(py::str(py::type::handle_of(solve).attr("__name__"))) +
                           ", not a function solve(B)");
    auto holder = std::shared_ptr<py::object>(new py::object(solve), [](py::object* p) {
      py::gil_scoped_acquire gil;
      delete p;
    });
    return [holder, name, iterative](const DenseMatrix& B, DenseMatrix& X) {
      py::gil_scoped_acquire gil;
      const py::object x = iterative ? (*holder)(to_numpy(B), to_numpy(X)) : (*holder)(to_numpy(B));
      DenseMatrix solution = dense_from(x, "solver " + name + ": the solution");
      if (solution.rows() != B.rows() || solution.cols() != B.cols())
        throw py::value_error("solver " + name + ": solve returned " +
                              std::to_string(solution.rows()) + " x " +
                              std::to_string(solution.cols()) + " for B of " +
                              std::to_string(B.rows()) + " x " + std::to_string(B.cols()));
      X = std::move(solution);
    };
  };
  // The factory first: a flow that starts once the row is there finds it.
  factories()[py::str(name)] = factory;
  py::gil_scoped_release nogil;  // waits for a flow another thread runs, whose callbacks need it
  mcfbench::register_solver(std::move(d));
}

std::string run(const std::string& config, const std::string& out, bool quick,
                const std::string& shard, bool force, py::handle threads, py::handle max_memory) {
  RunOptions o;
  o.out = out;
  o.quick = quick;
  o.shard = shard;
  o.force = force;
  if (!threads.is_none()) o.threads = threads.cast<int>();
  if (!max_memory.is_none()) o.max_memory = py::str(max_memory);
  int status;
  {
    py::gil_scoped_release nogil;
    status = mcfbench::run(config, o);
    std::fflush(nullptr);  // its summary line, before Python prints anything
  }
  if (status == 130) {
    PyErr_SetNone(PyExc_KeyboardInterrupt);
    throw py::error_already_set();
  }
  if (status > 128)
    throw std::runtime_error("mcfbench.run: stopped by signal " + std::to_string(status - 128) +
                             "; the finished cells are kept, run again to resume");
  if (status != 0)
    throw std::runtime_error("mcfbench.run: " + config +
                             ": a cell ended in an error (status "
                             "\"error\" in its result file in " +
                             out + "; mcfbench.results(out) lists it); the other cells are kept");
  return out;
}

py::object results(const std::string& folder) {
  ResultsTable t;
  {
    py::gil_scoped_release nogil;
    t = mcfbench::results(folder);
  }
  py::module_ pandas;
  try {
    pandas = py::module_::import("pandas");
  } catch (const py::error_already_set& e) {
    if (!e.matches(PyExc_ImportError)) throw;
    throw py::import_error("mcfbench.results needs pandas (Debian: python3-pandas)");
  }
  py::dict columns;
  for (std::size_t c = 0; c < t.columns.size(); ++c) {
    py::list values;
    for (const auto& row : t.rows)
      values.append(row[c] ? std::visit([](const auto& v) { return py::cast(v); }, row[c]->value)
                           : py::none());
    columns[py::str(t.columns[c])] = values;
  }
  return pandas.attr("DataFrame")(columns, "columns"_a = t.columns);
}

/// The keyword list of flow()'s docstring, from the schema.
std::string options_doc() {
  std::string s;
  for (const OptionInfo& o : flow_options()) {
    s += "    " + o.name + " (" + o.values + "; default " + o.fallback + ")\n        " + o.help +
         ". Config key " + o.key + ".\n";
  }
  return s;
}

}  // namespace
}  // namespace mcfbench::python

PYBIND11_MODULE(mcfbench, m) {
  using namespace mcfbench::python;
  m.doc() =
      "mcfbench: mean-curvature flow on triangle meshes (MCF, conformalized MCF, heat flow) with\n"
      "hat and octree finite elements and the harness's solvers, as a library (docs/python.md).\n\n"
      "flow(V, F, **options) or flow(mesh=SPEC, **options): one flow, as `mcfbench flow` runs it\n"
      "matrices(V, F, basis=...): the mass and stiffness matrices M, K\n"
      "register_solver(name, factory): a solver written in Python, for flows and studies\n"
      "run(config, out): an experiment config's cells, as `mcfbench run` runs them\n"
      "results(folder): a results folder as a pandas DataFrame, one row per cell\n"
      "load_mesh(spec), mesh_info(...): a mesh as a flow loads it, and its report\n"
      "flow_options(): every option of flow\n";
  m.attr("_solver_factories") = py::dict();

  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const mcfbench::InputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });

  py::class_<FlowOutput>(m, "FlowResult",
                         "What flow() returns.\n\n"
                         "V: n x 3 float64 array, the final positions (the input's vertex order)\n"
                         "F: m x 3 int64 array, the faces (as loaded: oriented, repaired)\n"
                         "frames: {step: n x 3 array} with save_every=K (step 0 and every K-th)\n"
                         "result: dict, what `mcfbench flow` writes to result.json")
      .def_readonly("V", &FlowOutput::V)
      .def_readonly("F", &FlowOutput::F)
      .def_readonly("frames", &FlowOutput::frames)
      .def_readonly("result", &FlowOutput::result)
      .def("__repr__", [](const FlowOutput& o) {
        return "<mcfbench.FlowResult: " + std::string(py::str(o.result["status"])) + " after " +
               std::string(py::str(o.result["stop"]["step"])) + " steps, " +
               std::to_string(o.V.shape(0)) + " vertices>";
      });

  m.def(
      "flow", &flow, "V"_a = py::none(), "F"_a = py::none(), py::kw_only(),
      "callback"_a = py::none(), "config"_a = py::none(), "max_memory"_a = py::none(),
      "progress"_a = false,
      ("flow(V=None, F=None, *, callback=None, config=None, max_memory=None, progress=False, "
       "**options) -> FlowResult\n\n"
       "Runs one flow, as `mcfbench flow` does, and returns its final positions, frames and\n"
       "result record (FlowResult: .V, .F, .frames, .result).\n\n"
       "The mesh: arrays V (n x 3, float) and F (m x 3, int32 or int64, 0-based), kept in\n"
       "their frame; or mesh=SPEC among the options (\"cgal:bunny00\", \"sphere:vertices=2000\",\n"
       "a file path; files and catalogue models are scaled into the unit cube).\n\n"
       "callback(step, t, V): called after every step (step 0: the input) with a copy of the\n"
       "positions; return True to end the flow there (result['stop']['reason'] is then\n"
       "'stopped by the caller'). config: a dict of flow config keys (result.json's 'config'),\n"
       "or a JSON file's path; keywords override it. max_memory: refuse a flow whose estimated\n"
       "peak exceeds this ('8G', 'none'). progress: the progress line on stderr.\n\n"
       "A flow that turns singular returns with result['status'] == 'singular'. Unknown or\n"
       "out-of-range options, bad arrays and bad meshes raise ValueError (TypeError for a\n"
       "value of the wrong kind), naming the key or face, before anything runs. An exception\n"
       "in the callback or in a registered solver ends the flow and is raised again.\n\n"
       "Options (keywords; the flags of `mcfbench flow`, '-' written '_'; None = default):\n" +
       options_doc())
          .c_str());

  m.def("matrices", &matrices, "V"_a = py::none(), "F"_a = py::none(), py::kw_only(),
        "config"_a = py::none(),
        "matrices(V=None, F=None, *, config=None, **options) -> (M, K)\n\n"
        "The mass matrix M_IJ = int B_I B_J dA and the stiffness K_IJ = int grad B_I . grad B_J\n"
        "dA (positive semi-definite; the Laplacian is -K) of the basis the options name on\n"
        "the mesh (V, F, or mesh=SPEC) at its initial embedding: scipy.sparse.csc_matrix, or\n"
        "without scipy a dict of CSR arrays (data, indices, indptr, shape; the matrices are\n"
        "symmetric). Options as flow's: basis ('hat', 'octree'), mass ('consistent',\n"
        "'lumped'), depth, cubature, ... The hat basis's rows are the mesh's vertices.");

  m.def("load_mesh", &load_mesh, "spec"_a, py::kw_only(), "config"_a = py::none(),
        "load_mesh(spec, *, config=None, **options) -> (V, F)\n\n"
        "A mesh spec loaded and validated as a flow with these options loads it: files and\n"
        "catalogue models scaled into the unit cube, faces oriented consistently.");

  m.def("mesh_info", &mesh_info, "V"_a = py::none(), "F"_a = py::none(), py::kw_only(),
        "config"_a = py::none(),
        "mesh_info(V=None, F=None, *, config=None, **options) -> dict\n\n"
        "What `mcfbench mesh-info` prints of a mesh (arrays V, F, or mesh=SPEC), loaded and\n"
        "validated as a flow with these options loads it: vertices, faces, boundary_loops,\n"
        "connected_components, genus, area, bbox_min, bbox_max, reoriented_faces, ..., and\n"
        "notes where loading changed something.");

  m.def("register_solver", &register_solver, "name"_a, "factory"_a, py::kw_only(),
        "iterative"_a = false, "help"_a = "",
        "register_solver(name, factory, *, iterative=False, help='')\n\n"
        "Adds a solver written in Python: solver=name then selects it in flow() and in the\n"
        "'solver.name' axis of experiment configs run by run().\n\n"
        "factory(A) is called with each new system matrix (scipy.sparse.csc_matrix, symmetric\n"
        "positive definite; every step of MCF and cMCF) and returns solve(B) -> X for it:\n"
        "B is n x 3 (one column per coordinate), X must be n x 3. With iterative=True it is\n"
        "called as solve(B, X0) with the flow's prediction X0. Each solve is timed and\n"
        "recorded as a built-in solver's (its true relative residual computed by mcfbench).\n"
        "Registering a name again replaces the factory; a built-in name is a ValueError.\n\n"
        "    import scipy.sparse.linalg as sla\n"
        "    mcfbench.register_solver('splu', lambda A: sla.splu(A).solve)\n");

  m.def("run", &run, "config"_a, "out"_a, py::kw_only(), "quick"_a = false, "shard"_a = "0/1",
        "force"_a = false, "threads"_a = py::none(), "max_memory"_a = py::none(),
        "run(config, out, *, quick=False, shard='0/1', force=False, threads=None, "
        "max_memory=None) -> out\n\n"
        "Runs an experiment config's cells into the folder out, as `mcfbench run` does (the same\n"
        "progress on stderr; finished cells skipped, so a stopped run resumes). Solvers\n"
        "registered with register_solver may appear in its axes. Returns out. A bad config\n"
        "raises ValueError before anything is written; a cell that ended in an error raises\n"
        "RuntimeError after the others ran; Ctrl-C stops after the running step\n"
        "(KeyboardInterrupt).");

  m.def("results", &results, "folder"_a,
        "results(folder) -> pandas.DataFrame\n\n"
        "A results folder's cells, one row per cell result file: the flow config's keys\n"
        "('mesh', 'solver.name', 'dt', ...), the cell's ('cell.index', 'cell.repetition', ...)\n"
        "and every other scalar of the file by its dotted path ('status', 'stop.reason',\n"
        "'timing.step_median_seconds', 'reference_distance.rms', ...).");

  m.def(
      "flow_options",
      [] {
        py::list out;
        for (const mcfbench::OptionInfo& o : mcfbench::flow_options())
          out.append(py::dict("name"_a = o.name, "flag"_a = o.flag, "key"_a = o.key,
                              "values"_a = o.values, "default"_a = o.fallback, "help"_a = o.help,
                              "switch"_a = o.switch_only));
        return out;
      },
      "flow_options() -> list of dict: every keyword flow() takes (name, flag, key, values,\n"
      "default, help, switch: True for a flag that takes no value on the command line).");
}
