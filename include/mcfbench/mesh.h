#pragma once
// A triangle mesh as mcfbench loads it for a flow: read from a mesh spec (a generator, a model of
// the catalogue, a file) or taken from arrays, checked and validated (docs/flow.md#validation).

#include "mcfbench/export.h"
#include "mcfbench/types.h"

#include <memory>
#include <string>

namespace mcfbench {

class MCFBENCH_API Mesh {
 public:
  /// Loads a mesh as a flow with `options` would (docs/flow.md#mesh-specs).
  /// Inputs:
  ///   spec     a mesh spec: "sphere:vertices=2000", "cgal:bunny00", "cgal:armadillo@faces=208000",
  ///            "path/to/mesh.off"; files and catalogue models are scaled into the unit cube
  ///   options  what decides how zero-area faces are treated: "basis" (the octree keeps them),
  ///            "repair-degenerate" (removes them); other keys are read and checked too
  /// Output: the mesh, its faces oriented consistently, validated.
  /// Throws InputError naming the spec (and the file, line or face) on any problem.
  static Mesh load(const std::string& spec, const Options& options = {});

  /// The same checks for a mesh given as arrays, which keep their frame (no scaling).
  /// Inputs:
  ///   V        n x 3 vertex positions, finite
  ///   F        m x 3 faces, 0-based indices into V's rows; faces listed with mixed orientation
  ///            are reoriented as a file's are
  ///   options  as for load()
  ///   name     stands for the mesh in messages and in the result's "mesh.spec"
  /// Output: the mesh (its own copy of V and F). Throws InputError naming `name` and the face or
  /// vertex: a corner out of range or repeated, a non-finite coordinate, a non-manifold edge or
  /// vertex, a non-orientable surface, an empty mesh, a zero-area face the options refuse.
  static Mesh from_arrays(const Vertices& V, const Faces& F, const Options& options = {},
                          const std::string& name = "arrays");

  const Vertices& vertices() const;  ///< n x 3, as loaded (scaled, reoriented, repaired)
  const Faces& faces() const;        ///< m x 3
  const std::string& spec() const;   ///< the spec, or the arrays' name
  /// What loading found, as JSON text: what `mcfbench mesh-info` prints (vertices, faces,
  /// boundary_loops, connected_components, genus, area, bbox_min, bbox_max, reoriented_faces,
  /// ...; "notes" when loading changed something).
  std::string report_json() const;

  struct Impl;
  /// The library's own view (internal).
  const Impl& impl() const { return *impl_; }

 private:
  explicit Mesh(std::shared_ptr<const Impl> impl);
  std::shared_ptr<const Impl> impl_;  // immutable, shared by copies
};

}  // namespace mcfbench
