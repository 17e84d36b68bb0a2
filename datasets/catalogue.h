#pragma once
// Real models from Debian's libcgal-demo (data.tar.gz), extracted on first use into a cache
// ($MCFBENCH_CACHE, default ~/.cache/mcfbench). Nothing is downloaded at run time.

#include "datasets/mesh.h"

#include <string>
#include <vector>

namespace mcf {

/// Names of the catalogued models (armadillo, bunny00, refined_elephant, mannequin-devil, knot1,
/// knot2, man, ...).
std::vector<std::string> catalogue_models();
/// Path of the cached OFF file, extracting it if needed. Throws MeshError naming the model and
/// the archive paths tried when the archive is missing (run scripts/setup.sh).
std::string catalogue_path(const std::string& model);

}  // namespace mcf
