#pragma once
// `mcfbench mesh-info SPEC`: a mesh spec loaded, validated and described.

#include "datasets/mesh_spec.h"

#include <nlohmann/json.hpp>

#include <string>

namespace mcf {

/// {spec, kind, analytic, vertices, faces, unreferenced_vertices, boundary_loops,
/// connected_components, euler_characteristic, genus, area, bbox_min, bbox_max,
/// reoriented_faces, repaired_faces, degenerate_faces[, notes][, sphere_radius][,
/// cylinder_radius]} of the mesh `spec` gives, loaded with `options`. When `write_to` is not
/// empty the (generated / scaled / repaired / subdivided) mesh is also written there, before the
/// description is returned: a write that fails throws.
nlohmann::json mesh_info(const std::string& spec, const std::string& write_to,
                         const MeshLoadOptions& options = {});

/// The same description of a mesh already loaded (a mesh given as arrays too).
nlohmann::json mesh_description(const MeshSource& mesh);

}  // namespace mcf
