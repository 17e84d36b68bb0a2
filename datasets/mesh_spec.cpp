// Mesh-spec strings: `name[:k=v,...][@faces=N]`, `cgal:MODEL[@faces=N]` or a file path.
// Strict on purpose: a typo in a benchmark config must fail, not silently run the default.

#include "datasets/mesh_spec.h"

#include "datasets/referenced_vertices.h"

#include "datasets/catalogue.h"
#include "datasets/generators.h"
#include "datasets/mesh_io.h"
#include "datasets/repair.h"
#include "datasets/subdivide.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <map>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

namespace mcf {
namespace {

// The most faces a mesh spec may ask for, generated or by @faces (~10 GB of mesh and topology).
constexpr long long kMaxFaces = 200'000'000;
// Integer keys beyond this are refused before they reach an int (the counts that matter are far
// smaller; kMaxFaces bounds their products).
constexpr double kMaxInteger = 1e9;

struct Param {
  std::string key;
  bool integer;
  double fallback;
  std::string help;
  double max = kMaxInteger;  ///< integer keys: the largest value taken (in magnitude)
};

using Values = std::map<std::string, double>;

struct Generator {
  std::string name;
  std::vector<Param> params;
  std::function<TriangleMesh(const Values&)> build;
  std::string help;
  /// About how many faces `build` makes (an upper estimate, in double so that it cannot
  /// overflow): checked against kMaxFaces before building, since the generators count in int.
  std::function<double(const Values&)> faces;
};

int as_int(const Values& v, const std::string& k) {
  return static_cast<int>(v.at(k));
}

const std::vector<Generator>& generators() {
  static const std::vector<Generator> table = {
      {"sphere",
       {{"vertices", true, 10242, "target vertex count"}, {"radius", false, 1.0, "radius"}},
       [](const Values& v) {
         return make_sphere(static_cast<long long>(v.at("vertices")), v.at("radius"));
       },
       "geodesic sphere with about `vertices` vertices, centred at the origin",
       [](const Values& v) {  // make_sphere's frequency k (10 k^2 + 2 vertices, 20 k^2 faces)
         const double k = std::max(1.0, std::round(std::sqrt((v.at("vertices") - 2) / 10.0)));
         return 20 * k * k;
       }},
      {"icosphere",
       {{"level", true, 5, "1-to-4 subdivisions of the icosahedron", 12},
        {"radius", false, 1.0, "radius"}},
       [](const Values& v) { return make_icosphere(as_int(v, "level"), v.at("radius")); },
       "icosahedron subdivided `level` times (10*4^level+2 vertices)",
       [](const Values& v) { return 20 * std::pow(4.0, v.at("level")); }},
      {"torus",
       {{"R", false, 1.0, "major radius"},
        {"r", false, 0.3, "minor radius"},
        {"n_major", true, 96, "segments around the axis"},
        {"n_minor", true, 32, "segments around the tube"}},
       [](const Values& v) {
         return make_torus(v.at("R"), v.at("r"), as_int(v, "n_major"), as_int(v, "n_minor"));
       },
       "torus about z (genus 1)",
       [](const Values& v) { return 2 * v.at("n_major") * v.at("n_minor"); }},
      {"spiral",
       {{"turns", true, 3, "turns"},
        {"segments_per_turn", true, 128, "segments along one turn"},
        {"profile_segments", true, 8, "segments across the ribbon"}},
       [](const Values& v) {
         return make_cubical_spiral(as_int(v, "turns"), as_int(v, "segments_per_turn"),
                                    as_int(v, "profile_segments"));
       },
       "cubical spiral: square-profile helical ribbon with boundary",
       [](const Values& v) {
         return 2 * 4 * std::ceil(v.at("segments_per_turn") / 4) * v.at("turns") *
                v.at("profile_segments");
       }},
      {"dumbbell",
       {{"resolution", true, 64, "vertices around"}},
       [](const Values& v) { return make_dumbbell(as_int(v, "resolution")); },
       "two unit spheres joined by a thin neck (genus 0)",
       [](const Values& v) { return 2 * v.at("resolution") * v.at("resolution"); }},
      {"rounded_cylinder",
       {{"radius", false, 0.5, "radius"},
        {"length", false, 2.0, "length of the straight part"},
        {"resolution", true, 64, "vertices around"}},
       [](const Values& v) {
         return make_rounded_cylinder(v.at("radius"), v.at("length"), as_int(v, "resolution"));
       },
       "closed capsule (cylinder with hemispherical caps)",
       [](const Values& v) {  // rings spaced as the widest ring's vertices along the profile
         // (at least 2 rows, rounded), each of at most max(6, n) vertices; F = 2 V - 4.
         const double n = v.at("resolution"), r = v.at("radius"), l = v.at("length");
         const double rows = n * (std::numbers::pi * r + l) / (2 * std::numbers::pi * r);
         return 2 * std::max(6.0, n) * std::max(2.0, rows + 1);
       }},
      {"open_cylinder",
       {{"radius", false, 0.5, "radius"},
        {"length", false, 2.0, "length"},
        {"n_around", true, 64, "vertices around"},
        {"n_along", true, 40, "segments along"}},
       [](const Values& v) {
         return make_open_cylinder(v.at("radius"), v.at("length"), as_int(v, "n_around"),
                                   as_int(v, "n_along"));
       },
       "open cylinder (two boundary loops)",
       [](const Values& v) { return 2 * v.at("n_around") * v.at("n_along"); }},
      {"catenoid",
       {{"waist", false, 1.0, "waist radius"},
        {"height", false, 1.0, "half height h (z in [-h, h])"},
        {"n_around", true, 64, "vertices around"},
        {"n_along", true, 24, "segments along"}},
       [](const Values& v) {
         return make_catenoid(v.at("waist"), v.at("height"), as_int(v, "n_around"),
                              as_int(v, "n_along"));
       },
       "catenoid (minimal surface, two boundary loops)",
       [](const Values& v) { return 2 * v.at("n_around") * v.at("n_along"); }},
  };
  return table;
}

[[noreturn]] void fail(const std::string& spec, const std::string& problem) {
  throw MeshError("mesh spec '" + spec + "': " + problem);
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

bool looks_like_file(const std::string& s) {
  if (s.find('/') != std::string::npos) return true;
  const std::string l = lower(s);
  for (const char* ext : {".off", ".ply", ".obj", ".stl"})
    if (l.size() > 4 && l.compare(l.size() - 4, 4, ext) == 0) return true;
  return false;
}

// Whole-string numbers only: "12abc", "", "1e400" and "nan" are errors, and so is "1.5" for an
// integer key.
double parse_number(const std::string& spec, const std::string& key, const std::string& text,
                    bool integer) {
  const char* begin = text.c_str();
  char* end = nullptr;
  errno = 0;
  double value;
  if (integer) {
    const long long v = std::strtoll(begin, &end, 10);
    value = static_cast<double>(v);
  } else {
    value = std::strtod(begin, &end);
  }
  if (text.empty() || end != begin + text.size() || errno == ERANGE || !std::isfinite(value))
    fail(spec, "key '" + key + "' needs " + (integer ? "an integer" : "a number") + ", got '" +
                   text + "'");
  return value;
}

std::string param_list(const Generator& g) {
  std::string s;
  for (const auto& p : g.params) s += (s.empty() ? "" : ", ") + p.key;
  return s;
}

}  // namespace

void fit_unit_cube(TriangleMesh& mesh) {
  if (mesh.num_vertices() == 0) return;
  // The surface's box: a vertex no face uses is moved along but does not size the model (one
  // stray vertex at 100 x the model's size shrank it 100-fold, seven octree levels).
  const Bounds box = surface_bounds(mesh);
  const Eigen::RowVector3d extent = box.extent();
  const double scale = extent.maxCoeff() > 0 ? 1.0 / extent.maxCoeff() : 1.0;
  // Uniform scale (shape kept); the shorter axes are centred in [0, 1].
  const Eigen::RowVector3d offset = 0.5 * (Eigen::RowVector3d::Ones() - scale * extent);
  mesh.vertices = ((mesh.vertices.rowwise() - box.lo) * scale).rowwise() + offset;
  // The long axis can round an ulp outside [0, 1] (cgal:bunny00's smallest x came out -2.1e-17),
  // and the octree's "auto" cube would then leave the unit cube for the tight one: clamp the
  // rounding away (it moves no coordinate by more than a few ulps). Unused vertices may lie
  // anywhere and keep their place relative to the surface.
  for (Eigen::Index v = 0; v < mesh.num_vertices(); ++v) {
    auto p = mesh.vertices.row(v);
    if ((p.array() >= -1e-12).all() && (p.array() <= 1.0 + 1e-12).all())
      p = p.cwiseMax(0.0).cwiseMin(1.0);
  }
}

namespace {

/// Splits "@faces=N" off `spec`: returns N (0 without it) and leaves the rest in `head`.
long long split_face_target(const std::string& spec, std::string& head) {
  head = spec;
  const auto at = spec.rfind('@');
  if (at == std::string::npos || looks_like_file(spec.substr(at + 1))) return 0;
  head = spec.substr(0, at);
  const std::string mod = spec.substr(at + 1);
  const auto eq = mod.find('=');
  const std::string key = mod.substr(0, eq);
  if (key != "faces" || eq == std::string::npos)
    fail(spec, "unknown modifier key '" + key + "' (only @faces=N)");
  const long long target_faces =
      static_cast<long long>(parse_number(spec, "faces", mod.substr(eq + 1), true));
  if (target_faces < 1 || target_faces > kMaxFaces)
    fail(spec,
         "key 'faces' must be in 1.." + std::to_string(kMaxFaces) + ", got " + mod.substr(eq + 1));
  return target_faces;
}

/// The generator's values: its defaults, overridden by the spec's key=value items (`args` is
/// empty and `given` false for "NAME" alone), each key known, given once and in range.
Values generator_values(const std::string& spec, const Generator& g, const std::string& args,
                        bool given) {
  Values values;
  for (const auto& p : g.params) values[p.key] = p.fallback;
  std::vector<std::string> seen;
  size_t pos = 0;
  while (given && pos <= args.size()) {
    const size_t comma = std::min(args.find(',', pos), args.size());
    const std::string item = args.substr(pos, comma - pos);
    pos = comma + 1;
    const auto eq = item.find('=');
    const std::string key = item.substr(0, eq);
    if (eq == std::string::npos || key.empty())
      fail(spec, "expected key=value, got '" + item + "' (keys of " + g.name + ": " +
                     param_list(g) + ")");
    auto p = std::find_if(g.params.begin(), g.params.end(),
                          [&](const Param& x) { return x.key == key; });
    if (p == g.params.end())
      fail(spec, "unknown key '" + key + "' for " + g.name + " (keys: " + param_list(g) + ")");
    if (std::find(seen.begin(), seen.end(), key) != seen.end())
      fail(spec, "key '" + key + "' given twice");
    seen.push_back(key);
    values[key] = parse_number(spec, key, item.substr(eq + 1), p->integer);
    if (p->integer && std::abs(values[key]) > p->max)
      fail(spec, "key '" + key + "' is out of range (at most " +
                     std::to_string(static_cast<long long>(p->max)) + "), got " +
                     item.substr(eq + 1));
  }
  // Values the generators refuse (a count or size <= 0) are theirs to name; a size that would
  // overflow their int counts or exhaust memory is refused here, before anything is built.
  if (std::all_of(values.begin(), values.end(), [](const auto& kv) { return kv.second > 0; })) {
    const double faces = g.faces(values);
    if (!(faces <= static_cast<double>(kMaxFaces)))
      fail(spec, "these values make about " +
                     std::to_string(static_cast<long long>(std::min(faces, 1e18))) +
                     " faces, more than the " + std::to_string(kMaxFaces) + " a mesh may have");
  }
  return values;
}

const Generator& find_generator(const std::string& spec, const std::string& name) {
  const auto& table = generators();
  auto g =
      std::find_if(table.begin(), table.end(), [&](const Generator& x) { return x.name == name; });
  if (g == table.end()) {
    std::string known = "cgal";
    for (const auto& x : table) known += ", " + x.name;
    fail(spec, "unknown generator '" + name + "' (known: " + known + ", or a file path)");
  }
  return *g;
}

/// The mesh generator `g` builds from `values` (parse_mesh_spec's) into `src`; errors name `spec`.
void load_generated(const std::string& spec, const Generator& g, const Values& values,
                    MeshSource& src) {
  const std::string& name = g.name;
  src.kind = name;
  src.analytic = true;
  try {
    src.mesh = g.build(values);
    // As read_mesh does for files: then every MeshSource's faces hold in a half-edge mesh,
    // and a flow writes them without checking each frame again (FaceCheck::trusted).
    check_half_edge_faces(src.mesh, name);
  } catch (const MeshError& e) {
    fail(spec, e.what());
  }
  if (name == "sphere" || name == "icosphere") src.sphere_radius = values.at("radius");
  if (name == "open_cylinder") src.cylinder_radius = values.at("radius");
  // The spiral stands in for the paper's cubical spiral *model*, and the paper scales every
  // model but the sphere into the unit cube (docs/design.md "Conventions"): so does this one, or
  // table1's δ and octree would see a 2 x 2 x 3.6 shape instead.
  if (name == "spiral") {
    src.analytic = false;
    fit_unit_cube(src.mesh);
  }
}

/// "@faces=N": subdivides to about N faces, with the midpoints of an analytic sphere or
/// cylinder put back onto it.
void subdivide_source(MeshSource& src, long long target_faces) {
  src.mesh = subdivide_to_faces(src.mesh, target_faces);
  // Midpoints of a sphere lie inside it; put them back so sphere_radius stays exact.
  if (src.sphere_radius)
    src.mesh.vertices = src.mesh.vertices.rowwise().normalized() * *src.sphere_radius;
  // Likewise chord midpoints around a cylinder: back onto radius r about the z axis.
  if (src.cylinder_radius)
    for (Eigen::Index v = 0; v < src.mesh.vertices.rows(); ++v) {
      const double rho = std::hypot(src.mesh.vertices(v, 0), src.mesh.vertices(v, 1));
      src.mesh.vertices(v, 0) *= *src.cylinder_radius / rho;
      src.mesh.vertices(v, 1) *= *src.cylinder_radius / rho;
    }
}

}  // namespace

MeshSpecRequest parse_mesh_spec(const std::string& spec) {
  MeshSpecRequest r;
  r.spec = spec;
  std::string head;
  r.target_faces = split_face_target(spec, head);
  if (head.empty()) fail(spec, "empty mesh spec");
  if (looks_like_file(head)) {
    r.kind = "file";
    r.target = head;
    return r;
  }
  const auto colon = head.find(':');
  r.kind = head.substr(0, colon);
  const std::string args = colon == std::string::npos ? "" : head.substr(colon + 1);
  if (r.kind == "cgal") {
    if (args.empty()) fail(spec, "cgal needs a model name, e.g. cgal:armadillo");
    r.target = args;
    return r;
  }
  const Generator& g = find_generator(spec, r.kind);
  r.parameters = generator_values(spec, g, args, colon != std::string::npos);
  // Negative values the generator refuses make nothing (icosphere's level 0 makes 20 faces).
  if (std::all_of(r.parameters.begin(), r.parameters.end(),
                  [](const auto& kv) { return kv.second >= 0; }))
    r.generated_faces = g.faces(r.parameters);
  return r;
}

namespace {

std::string count_of(long long n, const std::string& what) {
  return std::to_string(n) + " " + what + (n == 1 ? "" : "s");
}

}  // namespace

namespace {

/// What every mesh goes through once it is read or built, before anything uses it: the note of
/// the faces its reading reoriented, the zero-area faces treated as `options` says (before
/// subdivision, which would make four of each), subdivision to `target_faces` (0: none) and
/// validation under `validate_name`. Errors name `spec`.
void finish_loading(MeshSource& src, long long reoriented_faces, const MeshLoadOptions& options,
                    const std::string& validate_name, long long target_faces) {
  const std::string& spec = src.spec;
  const Eigen::Index faces_read = src.mesh.num_faces();
  if (reoriented_faces > 0)
    src.notes.push_back("reoriented " + std::to_string(reoriented_faces) + " of " +
                        count_of(faces_read, "face") +
                        " so that every face agrees with its neighbours (the file lists them "
                        "with mixed orientation)");
  DegenerateRepair repaired;
  if (options.degenerate == DegenerateFaces::repair) {
    repaired = repair_degenerate_faces(src.mesh);
    if (repaired.degenerate_faces > 0) {
      try {
        check_half_edge_faces(src.mesh, validate_name);
      } catch (const MeshError& e) {
        fail(spec, std::string("removing its zero-area faces left a mesh a half-edge mesh "
                               "cannot hold: ") +
                       e.what());
      }
      const long long collapsed = repaired.degenerate_faces - repaired.flipped_faces;
      src.notes.push_back(
          "removed " + count_of(repaired.degenerate_faces, "zero-area face") +
          " (repair_degenerate): " + std::to_string(repaired.flipped_faces) +
          " flipped away across their longest edge, " + std::to_string(collapsed) + " collapsed (" +
          std::to_string(repaired.removed_faces) + " of " + count_of(faces_read, "face") +
          " gone, " + std::to_string(repaired.merged_vertices) +
          (repaired.merged_vertices == 1 ? " vertex" : " vertices") + " merged into a neighbour)");
    }
  }
  if (target_faces > 0) subdivide_source(src, target_faces);
  ValidateOptions validate;
  validate.keep_degenerate = options.degenerate == DegenerateFaces::keep;
  validate.degenerate_hint = options.degenerate_hint;
  src.report = validate_mesh(src.mesh, validate_name, validate);
  src.report.reoriented_faces = reoriented_faces;
  src.report.repaired_faces = repaired.degenerate_faces;
  if (src.report.degenerate_faces > 0)
    src.notes.push_back("kept " + count_of(src.report.degenerate_faces, "zero-area face") +
                        " as they are");
}

}  // namespace

MeshSource load_mesh_spec(const std::string& spec, const MeshLoadOptions& options) {
  return load_mesh_spec(parse_mesh_spec(spec), options);
}

MeshSource load_mesh_spec(const MeshSpecRequest& request, const MeshLoadOptions& options) {
  MeshSource src;
  src.spec = request.spec;
  std::string validate_name = request.spec;
  ReadReport read;
  if (request.kind == "file") {
    src.kind = "file";
    src.mesh = read_mesh(request.target, &read);  // its errors name the file
    fit_unit_cube(src.mesh);
    validate_name = request.target;
  } else if (request.kind == "cgal") {
    src.kind = "cgal";
    try {
      src.mesh = read_mesh(catalogue_path(request.target), &read);
    } catch (const MeshError& e) {
      fail(request.spec, e.what());
    }
    fit_unit_cube(src.mesh);
  } else {
    load_generated(request.spec, find_generator(request.spec, request.kind), request.parameters,
                   src);
  }
  finish_loading(src, read.reoriented_faces, options, validate_name, request.target_faces);
  return src;
}

MeshSource mesh_source_from_arrays(TriangleMesh mesh, const std::string& name,
                                   const MeshLoadOptions& options) {
  MeshSource src;
  src.spec = name;
  src.kind = "arrays";
  src.mesh = std::move(mesh);
  const long long reoriented = orient_and_check_faces(src.mesh, name);
  finish_loading(src, reoriented, options, name, 0);
  return src;
}

std::string mesh_spec_help() {
  std::string s =
      "Mesh specs: NAME[:key=value,...][@faces=N] | cgal:MODEL[@faces=N] | "
      "path/to/file.{off,ply,obj,stl}[@faces=N]\n"
      "  @faces=N subdivides 1-to-4 until at least N faces. Files and cgal models are scaled\n"
      "  uniformly into the unit cube; generated shapes keep their size.\n"
      "Generators:\n";
  for (const auto& g : generators()) {
    s += "  " + g.name + " - " + g.help + "\n";
    for (const auto& p : g.params) {
      char buf[64];
      std::snprintf(buf, sizeof buf, p.integer ? "%.0f" : "%g", p.fallback);
      s += "      " + p.key + "=" + buf + "  " + p.help + "\n";
    }
  }
  s += "Catalogue (libcgal-demo data.tar.gz, see scripts/setup.sh):\n ";
  for (const auto& m : catalogue_models()) s += " cgal:" + m;
  s += "\n";
  return s;
}

}  // namespace mcf
