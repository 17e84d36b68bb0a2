#include "api/detail.h"

#include "datasets/mesh_info.h"

#include <nlohmann/json.hpp>

namespace mcfbench {
namespace {

/// A mesh as loaded, with its copies in the API's types.
std::shared_ptr<Mesh::Impl> impl_of(mcf::MeshSource source, const mcf::MeshLoadOptions& load) {
  auto impl = std::make_shared<Mesh::Impl>();
  impl->vertices = source.mesh.vertices;
  impl->faces = source.mesh.faces;
  impl->source = std::move(source);
  impl->load = load;
  return impl;
}

}  // namespace

Mesh::Mesh(std::shared_ptr<const Impl> impl) : impl_(std::move(impl)) {}

Mesh Mesh::load(const std::string& spec, const Options& options) {
  return detail::translated([&] {
    const mcf::FlowConfig config = detail::flow_config(options, spec);
    const mcf::MeshLoadOptions load = mcf::mesh_load_options(config);
    return Mesh(impl_of(mcf::load_mesh_spec(spec, load), load));
  });
}

Mesh Mesh::from_arrays(const Vertices& V, const Faces& F, const Options& options,
                       const std::string& name) {
  return detail::translated([&] {
    const mcf::FlowConfig config = detail::flow_config(options, name);
    const mcf::MeshLoadOptions load = mcf::mesh_load_options(config);
    mcf::TriangleMesh mesh{V, F};
    return Mesh(impl_of(mcf::mesh_source_from_arrays(std::move(mesh), name, load), load));
  });
}

const Vertices& Mesh::vertices() const {
  return impl_->vertices;
}

const Faces& Mesh::faces() const {
  return impl_->faces;
}

const std::string& Mesh::spec() const {
  return impl_->source.spec;
}

std::string Mesh::report_json() const {
  return mcf::mesh_description(impl_->source).dump();
}

}  // namespace mcfbench
