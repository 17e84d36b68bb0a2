#include "mcfbench/basis.h"

#include "api/detail.h"

#include "config/registry.h"

namespace mcfbench {

struct Basis::Impl {
  mcf::FlowConfig config;
  std::unique_ptr<mcf::Basis> basis;
  SparseMatrix mass, stiffness;

  void integrate(const mcf::Coefficients& x) {
    basis->update(x, true, true);
    mass = basis->mass();
    stiffness = basis->stiffness();
  }
};

Basis::Basis(const Mesh& mesh, const Options& options) : impl_(std::make_unique<Impl>()) {
  detail::translated([&] {
    impl_->config = detail::flow_config(options, mesh.spec());
    const mcf::MeshSource& source = mesh.impl().source;
    if (source.report.degenerate_faces > 0 &&
        mcf::mesh_load_options(impl_->config).degenerate != mcf::DegenerateFaces::keep)
      throw InputError(options.name + ": basis: the " + impl_->config.basis +
                       " basis needs every face's cotangents, and " + mesh.spec() + " has " +
                       std::to_string(source.report.degenerate_faces) +
                       " zero-area faces (load it with these options, or with "
                       "repair_degenerate)");
    impl_->basis = mcf::make_basis(impl_->config, source.mesh, source.analytic);
    impl_->integrate(impl_->basis->initial_coefficients());
  });
}

Basis::~Basis() = default;
Basis::Basis(Basis&&) noexcept = default;
Basis& Basis::operator=(Basis&&) noexcept = default;

std::string Basis::name() const {
  return impl_->basis->name();
}

Eigen::Index Basis::dimension() const {
  return impl_->basis->dimension();
}

DenseMatrix Basis::initial_coefficients() const {
  return impl_->basis->initial_coefficients();
}

void Basis::update(const DenseMatrix& x) {
  if (impl_->basis->rebuilds_every_step())
    throw InputError(
        "basis: the rebuilt octree's functions change with the surface; update() "
        "needs fixed functions (octree.tracking \"tracked\", or the hat basis)");
  if (x.rows() != dimension() || x.cols() != 3)
    throw InputError("basis: update: x is " + std::to_string(x.rows()) + " x " +
                     std::to_string(x.cols()) + ", the basis needs " + std::to_string(dimension()) +
                     " x 3");
  if (!x.allFinite()) throw InputError("basis: update: x has a non-finite entry");
  impl_->integrate(x);
}

const SparseMatrix& Basis::mass() const {
  return impl_->mass;
}

const SparseMatrix& Basis::stiffness() const {
  return impl_->stiffness;
}

Vertices Basis::evaluate_vertices(const DenseMatrix& x) const {
  if (x.rows() != dimension() || x.cols() != 3)
    throw InputError("basis: evaluate_vertices: x is " + std::to_string(x.rows()) + " x " +
                     std::to_string(x.cols()) + ", the basis needs " + std::to_string(dimension()) +
                     " x 3");
  return impl_->basis->evaluate_vertices(x);
}

std::vector<int> Basis::locked_functions() const {
  return impl_->basis->locked_functions();
}

Operators matrices(const Mesh& mesh, const Options& options) {
  Basis basis(mesh, options);
  return {basis.mass(), basis.stiffness()};
}

}  // namespace mcfbench
