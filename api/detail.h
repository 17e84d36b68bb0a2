#pragma once
// What the public API's implementation shares (not installed): the options read into a flow
// config through the schema `mcfbench flow` uses, the translation of the harness's errors into
// the API's, the lock that keeps to one flow per process, and a mesh's internal state.

#include "mcfbench/mesh.h"
#include "mcfbench/types.h"

#include "config/flow_config.h"
#include "datasets/mesh_spec.h"

#include <mutex>
#include <optional>
#include <string>

namespace mcfbench {

struct Mesh::Impl {
  mcf::MeshSource source;
  mcf::MeshLoadOptions load;  ///< how it was loaded (zero-area faces)
  Vertices vertices;
  Faces faces;
};

namespace detail {

/// The flow config of `options`: the config text, then every setting (a flag's name or a dotted
/// key) at its key, read by flow_config_from_json. `mesh`: a loaded mesh's spec, which options
/// naming another are refused beside (InputError); with `stand_in`, a spec that only fills the
/// required key where the options name none (a solver made without a mesh). Errors name
/// options.name, the key and, where the caller gave it under another name, that name.
mcf::FlowConfig flow_config(const Options& options, const std::optional<std::string>& mesh = {},
                            bool stand_in = false);

/// Runs f, turning the harness's errors about its input (ConfigError, MeshError,
/// std::invalid_argument) into InputError with the same message; anything else passes unchanged,
/// a caller's own exceptions too.
template <class F>
auto translated(F&& f) -> decltype(f());

/// Held while a flow or a study runs: their thread counts are process-wide settings.
std::mutex& run_lock();

/// One flow or study at a time: waits for another thread's to end. A call from inside a running
/// one (its step callback or solver) would wait for itself: that is an InputError naming `what`.
class RunScope {
 public:
  explicit RunScope(const std::string& what);
  ~RunScope();
  RunScope(const RunScope&) = delete;
  RunScope& operator=(const RunScope&) = delete;

  /// Whether this thread is inside a flow or study.
  static bool inside();

 private:
  std::unique_lock<std::mutex> lock_;
};

[[noreturn]] void rethrow_as_input_error();

template <class F>
auto translated(F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const InputError&) {
    throw;
  } catch (...) {
    rethrow_as_input_error();
  }
}

}  // namespace detail
}  // namespace mcfbench
