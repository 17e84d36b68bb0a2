#pragma once
// The OpenMesh half-edge mesh the mesh I/O builds (datasets/mesh_io.cpp) and reads STL into
// (datasets/stl_format.cpp).

#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>

#include <mutex>

namespace mcf::openmesh_detail {

// Double-precision points: the default traits store floats, which would round every coordinate
// of an ASCII file we read and of every file we write.
struct IoTraits : OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3d;
  using Normal = OpenMesh::Vec3d;
};
using IoMesh = OpenMesh::TriMesh_ArrayKernelT<IoTraits>;

// OpenMesh prints warnings (e.g. "complex edge") on its own streams; we report problems through
// MeshError instead, so its chatter only confuses logs of batch runs.
inline void silence_openmesh() {
  static std::once_flag once;
  std::call_once(once, [] {
    ::omerr().disable();
    ::omlog().disable();
    ::omout().disable();
  });
}

}  // namespace mcf::openmesh_detail
