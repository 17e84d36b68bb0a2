#pragma once
// One mesh-spec string names any mesh wherever a mesh is expected:
//   sphere:vertices=40000[,radius=1]   icosphere:level=6   torus[:R=1,r=0.3,...]   spiral
//   dumbbell   rounded_cylinder   open_cylinder   catenoid
//   cgal:armadillo   cgal:armadillo@faces=832000   path/to/file.off[@faces=N]
// "@faces=N" subdivides 1-to-4 until at least N faces (sphere/icosphere: new vertices are
// projected back onto the sphere so sphere_radius stays exact).
// Unknown generators, unknown or repeated keys and malformed numbers are errors naming the key;
// parameters and defaults are listed by mesh_spec_help().

#include "datasets/mesh.h"
#include "datasets/validate.h"

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace mcf {

struct MeshSource {
  /// Its faces hold in a half-edge mesh (read_mesh or load_mesh_spec checked them; subdivision
  /// keeps that), so writers may pass FaceCheck::trusted for it and its flowed copies.
  TriangleMesh mesh;
  std::string spec;       ///< as given
  std::string kind;       ///< "sphere", "icosphere", "cgal", "file", ...
  bool analytic = false;  ///< generated shape (keeps its size); real models are unit-cube scaled
  std::optional<double> sphere_radius;    ///< set for sphere and icosphere (centre at the origin)
  std::optional<double> cylinder_radius;  ///< set for open_cylinder (axis z through the origin)
  MeshReport report;                      ///< validation report (validate_mesh has passed)
  /// What loading changed or let through, one sentence each (faces reoriented, zero-area faces
  /// removed or kept), for the user to see on stderr; the counts are in `report`.
  std::vector<std::string> notes;
};

/// What to do with zero-area faces (validate.h's degenerate_faces).
enum class DegenerateFaces {
  refuse,  ///< a MeshError naming the first one (the default)
  keep,    ///< counted in MeshReport::degenerate_faces (a basis that needs no cotangents)
  repair,  ///< repair_degenerate_faces (datasets/repair.h), counted in repaired_faces
};

struct MeshLoadOptions {
  DegenerateFaces degenerate = DegenerateFaces::refuse;
  /// Appended to the refusal of a zero-area face: what the caller offers instead (an option).
  std::string degenerate_hint;
};

/// What a spec asks for, as load_mesh_spec reads it, before anything is built or read.
struct MeshSpecRequest {
  std::string spec;            ///< as given
  std::string kind;            ///< a generator's name, "cgal" or "file"
  std::string target;          ///< the file's path or the cgal model's name ("" for a generator)
  long long target_faces = 0;  ///< N of "@faces=N"; 0 without it
  double generated_faces = 0;  ///< a generator's upper estimate of the faces it makes (before
                               ///< @faces); 0 for files and cgal models, whose size is their
                               ///< own, and for negative values, which the generator refuses
  /// A generator's parameters, every one (the spec's values, the others' defaults).
  std::map<std::string, double> parameters;
};

/// Parses and checks the spec as load_mesh_spec does (the same MeshError on a malformed spec, an
/// unknown generator or key, or a size beyond the limit) without building, reading or extracting
/// anything: the file and the model are not looked at.
MeshSpecRequest parse_mesh_spec(const std::string& spec);

/// Parses the spec, builds/loads (a file's faces oriented consistently, read_mesh), scales real
/// models to the unit cube, treats zero-area faces as `options` says, subdivides to @faces,
/// validates. Throws MeshError naming the spec (and file) on any problem, including an unknown
/// generator or parameter.
MeshSource load_mesh_spec(const std::string& spec, const MeshLoadOptions& options = {});
/// The same from a spec parse_mesh_spec has read: nothing of it is parsed again.
MeshSource load_mesh_spec(const MeshSpecRequest& request, const MeshLoadOptions& options = {});

/// A mesh given as arrays (a library caller's, docs/library.md), loaded as a file is — every
/// face's corners checked, the faces oriented consistently, zero-area faces treated as `options`
/// says, validated — but not scaled: the caller's frame is kept. `name` stands for the spec in
/// messages and in MeshSource::spec; faces and vertices are named by their 0-based indices.
/// Throws MeshError naming `name` on any problem (an empty mesh, a non-finite coordinate, a corner
/// out of range or repeated, a non-manifold edge or vertex, a non-orientable surface).
MeshSource mesh_source_from_arrays(TriangleMesh mesh, const std::string& name,
                                   const MeshLoadOptions& options = {});

/// Uniform scale and translation into the unit cube [0,1]^3: the longest bounding-box side
/// becomes [0,1], the other axes are centred. What load_mesh_spec does to real models.
void fit_unit_cube(TriangleMesh& mesh);

/// Human-readable list of the supported specs (for --help).
std::string mesh_spec_help();

}  // namespace mcf
