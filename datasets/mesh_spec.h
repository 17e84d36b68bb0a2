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

#include <optional>
#include <string>

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
};

/// What a spec asks for, as load_mesh_spec reads it, before anything is built or read.
struct MeshSpecRequest {
  std::string kind;            ///< a generator's name, "cgal" or "file"
  std::string target;          ///< the file's path or the cgal model's name ("" for a generator)
  long long target_faces = 0;  ///< N of "@faces=N"; 0 without it
  double generated_faces = 0;  ///< a generator's upper estimate of the faces it makes (before
                               ///< @faces); 0 for files and cgal models, whose size is their
                               ///< own, and for negative values, which the generator refuses
};

/// Parses and checks the spec as load_mesh_spec does (the same MeshError on a malformed spec, an
/// unknown generator or key, or a size beyond the limit) without building, reading or extracting
/// anything: the file and the model are not looked at.
MeshSpecRequest parse_mesh_spec(const std::string& spec);

/// Parses the spec, builds/loads, scales real models to the unit cube, subdivides to @faces,
/// validates. Throws MeshError naming the spec (and file) on any problem, including an unknown
/// generator or parameter.
MeshSource load_mesh_spec(const std::string& spec);

/// Uniform scale and translation into the unit cube [0,1]^3: the longest bounding-box side
/// becomes [0,1], the other axes are centred. What load_mesh_spec does to real models.
void fit_unit_cube(TriangleMesh& mesh);

/// Human-readable list of the supported specs (for --help).
std::string mesh_spec_help();

}  // namespace mcf
